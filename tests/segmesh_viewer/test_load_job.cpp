#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <thread>

#include "segmesh/phantom.hpp"
#include "segmesh_io/write_mesh.hpp"
#include "segmesh_io/write_volume.hpp"
#include "segmesh_viewer/load_job.hpp"
#include "support/test_support.hpp"
#include "viewer_test_support.hpp"

namespace segmesh::viewer {
namespace {

namespace fs = std::filesystem;

LoadOutcome run_job(LoadRequest request) {
  LoadJob job;
  EXPECT_TRUE(job.start(std::move(request)));
  job.wait();
  std::optional<LoadOutcome> outcome = job.take_outcome();
  EXPECT_TRUE(outcome.has_value());
  return outcome ? std::move(*outcome) : LoadOutcome{};
}

ViewerState state_with_boxes() {
  ViewerState state;
  set_scene(state, test::three_boxes(), {}, "boxes", nullptr);
  select_part(state, 1);
  return state;
}

TEST(LoadInput, TheExtensionDecidesMeshOrVolume) {
  EXPECT_EQ(input_kind("a/scene.glb"), InputKind::mesh);
  EXPECT_EQ(input_kind("a/part.STL"), InputKind::mesh);
  EXPECT_EQ(input_kind("a/part.ply"), InputKind::mesh);
  EXPECT_EQ(input_kind("a/part.obj"), InputKind::mesh);
  EXPECT_EQ(input_kind("a/seg.nii.gz"), InputKind::volume);
  EXPECT_EQ(input_kind("a/seg.seg.nrrd"), InputKind::volume);
  EXPECT_EQ(input_kind(fs::temp_directory_path()), InputKind::volume);  // a DICOM folder
}

TEST(LoadJob, AMissingFileKeepsTheSceneAndSaysWhy) {
  ViewerState state = state_with_boxes();
  const fs::path missing = segmesh::test::scratch_dir("viewer_missing") / "nothing_here.nii.gz";
  LoadOutcome outcome = run_job({missing, nullptr, {}});
  EXPECT_EQ(outcome.kind, LoadOutcome::Kind::failed);
  EXPECT_NE(outcome.message.find("nothing_here.nii.gz"), std::string::npos) << outcome.message;
  finish_load(state, std::move(outcome));
  EXPECT_TRUE(state.message_is_error);
  ASSERT_EQ(state.scene.parts.size(), 3u);
  EXPECT_EQ(state.scene.parts[2].name, "implant_1");
  EXPECT_EQ(state.source, "boxes");
  EXPECT_EQ(state.selected, 1);
}

TEST(LoadJob, ACorruptFileOfEitherKindKeepsTheScene) {
  const fs::path dir = segmesh::test::scratch_dir("viewer_corrupt");
  for (const char* name : {"broken.nii.gz", "broken.glb", "broken.ply", "broken.nrrd"}) {
    std::ofstream(dir / name, std::ios::binary) << "this is not what the name says";
    ViewerState state = state_with_boxes();
    LoadOutcome outcome = run_job({dir / name, nullptr, {}});
    EXPECT_EQ(outcome.kind, LoadOutcome::Kind::failed) << name;
    EXPECT_FALSE(outcome.message.empty());
    finish_load(state, std::move(outcome));
    EXPECT_EQ(state.scene.parts.size(), 3u) << name;
    EXPECT_TRUE(state.message_is_error);
  }
}

TEST(LoadJob, AMeshFileIsReadAndMeasured) {
  const fs::path file = segmesh::test::scratch_dir("viewer_mesh_file") / "boxes.ply";
  write_scene(test::three_boxes(), file, MeshFormat::ply);
  ViewerState state;
  LoadOutcome outcome = run_job({file, nullptr, {}});
  ASSERT_EQ(outcome.kind, LoadOutcome::Kind::loaded) << outcome.message;
  EXPECT_EQ(outcome.result->kind, InputKind::mesh);
  EXPECT_EQ(outcome.result->image, nullptr);
  finish_load(state, std::move(outcome));
  EXPECT_FALSE(state.message_is_error);
  ASSERT_EQ(state.scene.parts.size(), 3u);
  ASSERT_EQ(state.stats.size(), 3u);
  EXPECT_NEAR(state.stats[0].volume_mm3, 4000, 1e-3);
  EXPECT_TRUE(state.stats[2].closed);
}

TEST(LoadJob, AVolumeIsMeshedByThePipelineAndKeptForRemeshing) {
  const fs::path file = segmesh::test::scratch_dir("viewer_volume") / "phantom.nii.gz";
  write_volume(make_phantom({{64, 64, 52}, {1.576, 1.576, 7.8}}), file);
  LoadOutcome outcome = run_job({file, nullptr, {}});
  ASSERT_EQ(outcome.kind, LoadOutcome::Kind::loaded) << outcome.message;
  const LoadResult& r = *outcome.result;
  ASSERT_NE(r.image, nullptr);
  ASSERT_FALSE(r.scene.parts.empty());
  bool bone = false, implant = false;
  for (const Part& p : r.scene.parts) {
    bone = bone || p.role == Role::bone;
    implant = implant || p.role == Role::implant;
  }
  EXPECT_TRUE(bone);
  EXPECT_TRUE(implant);
  for (const PartStats& s : r.stats) EXPECT_TRUE(s.closed);

  // Meshing again from the kept volume with only label 2 and Dual Contouring.
  MeshingOptions implant_only;
  implant_only.labels = {2};
  implant_only.method = Method::dual_contouring;
  LoadOutcome again = run_job({{}, r.image, implant_only});
  ASSERT_EQ(again.kind, LoadOutcome::Kind::loaded) << again.message;
  EXPECT_EQ(again.result->image, r.image);  // not read again
  for (const Part& p : again.result->scene.parts) EXPECT_EQ(p.label, 2);
}

TEST(LoadJob, ABadRequestForTheVolumeIsAMessage) {
  auto image = std::make_shared<const Image>(
      Image{"small.nii.gz", "int32", make_phantom({{32, 32, 26}, {3.15, 3.15, 15.6}}), {}});
  MeshingOptions missing_label;
  missing_label.labels = {9};
  LoadOutcome outcome = run_job({{}, image, missing_label});
  EXPECT_EQ(outcome.kind, LoadOutcome::Kind::failed);
  EXPECT_NE(outcome.message.find("9"), std::string::npos) << outcome.message;
}

TEST(LoadJob, CancellingStopsTheJobAndKeepsTheScene) {
  // A volume that takes far longer to mesh than the cancel takes to arrive.
  auto image = std::make_shared<const Image>(
      Image{"phantom", "int32", make_phantom({{256, 256, 203}, {0.394, 0.394, 2}}), {}});
  ViewerState state = state_with_boxes();
  LoadJob job;
  ASSERT_TRUE(job.start({{}, image, {}}));
  EXPECT_TRUE(job.status().running);
  EXPECT_FALSE(job.start({{}, image, {}}));  // one job at a time
  job.cancel();
  job.wait();
  EXPECT_FALSE(job.status().running);
  std::optional<LoadOutcome> outcome = job.take_outcome();
  ASSERT_TRUE(outcome.has_value());
  EXPECT_EQ(outcome->kind, LoadOutcome::Kind::cancelled);
  EXPECT_FALSE(outcome->result.has_value());
  finish_load(state, std::move(*outcome));
  EXPECT_EQ(state.scene.parts.size(), 3u);
  EXPECT_FALSE(state.message_is_error);
  EXPECT_FALSE(job.take_outcome().has_value());  // taken once

  // The job can run again after a cancel, and reports progress from the pipeline's steps.
  auto small = std::make_shared<const Image>(
      Image{"small", "int32", make_phantom({{32, 32, 26}, {3.15, 3.15, 15.6}}), {}});
  ASSERT_TRUE(job.start({{}, small, {}}));
  job.wait();
  outcome = job.take_outcome();
  ASSERT_TRUE(outcome.has_value());
  EXPECT_EQ(outcome->kind, LoadOutcome::Kind::loaded) << outcome->message;
  EXPECT_EQ(job.status().step, "measuring");
}

TEST(LoadJob, CancellingInTheMiddleOfThePipelineStopsIt) {
  auto image = std::make_shared<const Image>(
      Image{"phantom", "int32", make_phantom({{256, 256, 203}, {0.394, 0.394, 2}}), {}});
  LoadJob job;
  ASSERT_TRUE(job.start({{}, image, {}}));
  // Wait until the pipeline has named a step (the worker is inside build_scene), then cancel.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (job.status().running && job.status().step == "starting" &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  const std::string step = job.status().step;
  job.cancel();
  job.wait();
  const std::optional<LoadOutcome> outcome = job.take_outcome();
  ASSERT_TRUE(outcome.has_value());
  EXPECT_EQ(outcome->kind, LoadOutcome::Kind::cancelled) << "cancelled during step " << step;
}

}  // namespace
}  // namespace segmesh::viewer
