// The whole path on real public data (../shared/data): clinical label maps read, split and meshed
// into closed manifold parts (edges and vertices) whose counts agree with an independent count and
// whose volumes agree with the voxel volumes; every label of every readable label map meshed by
// both methods; Dual Contouring's triangles better than Marching Cubes' as extracted and after
// smoothing; grey-value CT at integer iso values; identical output for any thread count.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "segmesh/error.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh/phantom.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh/quality.hpp"
#include "segmesh/scene_measures.hpp"
#include "segmesh_io/read_volume.hpp"
#include "support/mesh_crossings.hpp"
#include "support/reference_components.hpp"
#include "support/test_support.hpp"

namespace segmesh {
namespace {

// Closed, edge-manifold and vertex-manifold (no pinch points), with a message naming the part.
void expect_closed_manifold(const MeshMeasures& m, const std::string& what) {
  EXPECT_TRUE(m.closed()) << what << ": boundary " << m.boundary_edges << ", non-manifold "
                          << m.nonmanifold_edges << ", winding " << m.winding_errors;
  EXPECT_EQ(m.nonmanifold_vertices, 0) << what << ": non-manifold vertices (pinch points)";
}

struct LabelTotals {
  int64_t parts = 0;
  double mesh_volume = 0;
  double voxel_volume = 0;
};

// Fraction of each label's voxels whose six face neighbours carry the same label. Marching Cubes
// at 0.5 cuts every convex voxel edge by a chamfer of 1/8 voxel area per voxel of length, so a
// structure one or two voxels thick (a rib at 3 mm) loses 10-20 % of its voxel volume in any
// midpoint Marching Cubes (VTK's discrete flying edges loses the same on this data); the 5 % bound
// applies to structures resolved by several voxels, which most of whose voxels are interior.
std::map<int32_t, double> interior_fraction(const LabelVolume& v) {
  std::map<int32_t, std::pair<int64_t, int64_t>> counts;  // interior, all
  const auto& d = v.grid.dims;
  for (int64_t k = 0; k < d[2]; ++k)
    for (int64_t j = 0; j < d[1]; ++j)
      for (int64_t i = 0; i < d[0]; ++i) {
        const int32_t l = v.at(i, j, k);
        if (l == 0) continue;
        bool interior = i > 0 && j > 0 && k > 0 && i + 1 < d[0] && j + 1 < d[1] && k + 1 < d[2];
        interior = interior && v.at(i - 1, j, k) == l && v.at(i + 1, j, k) == l &&
                   v.at(i, j - 1, k) == l && v.at(i, j + 1, k) == l && v.at(i, j, k - 1) == l &&
                   v.at(i, j, k + 1) == l;
        counts[l].first += interior;
        ++counts[l].second;
      }
  std::map<int32_t, double> out;
  for (const auto& [l, c] : counts) out[l] = double(c.first) / double(c.second);
  return out;
}

// Meshes every label and checks each part; returns per-label totals.
std::map<int32_t, LabelTotals> mesh_and_check(const Image& image, int connectivity, Method method) {
  const Scene scene = build_scene(image, {.method = method, .connectivity = connectivity});
  std::map<int32_t, LabelTotals> totals;
  for (const Part& part : scene.parts) {
    const MeshMeasures m = measure_mesh(part.mesh);
    expect_closed_manifold(m, image.path + " " + part.name);
    EXPECT_EQ(m.degenerate_triangles, 0) << part.name;
    EXPECT_GT(m.volume_mm3, 0) << part.name;
    LabelTotals& t = totals[part.label];
    ++t.parts;
    t.mesh_volume += m.volume_mm3;
    t.voxel_volume += part.voxel_volume_mm3;
    // Large parts keep their voxel volume closely; small ones lose the chamfered corners.
    if (part.voxels >= 5000) {
      EXPECT_NEAR(m.volume_mm3, part.voxel_volume_mm3, 0.05 * part.voxel_volume_mm3) << part.name;
    }
  }
  return totals;
}

// Connected components per non-zero label, by the independent breadth-first search.
std::map<int32_t, int64_t> reference_parts(const LabelVolume& labels, int connectivity) {
  int count = 0;
  const auto comp = test::reference_label_components(labels, connectivity, count);
  std::map<int32_t, int64_t> expected;
  std::vector<bool> seen(count, false);
  for (size_t i = 0; i < comp.size(); ++i) {
    if (comp[i] >= 0 && !seen[comp[i]]) {
      seen[comp[i]] = true;
      ++expected[labels.voxels[i]];
    }
  }
  return expected;
}

void check_label_map(const std::filesystem::path& file, int connectivity = 26,
                     Method method = Method::marching_cubes) {
  SCOPED_TRACE(std::string(method_name(method)));
  const Image image = read_volume(file);
  const auto totals = mesh_and_check(image, connectivity, method);
  // Part counts per label against a breadth-first search over the voxels.
  const LabelVolume labels = image.labels_int32();
  auto expected = reference_parts(labels, connectivity);
  ASSERT_EQ(totals.size(), expected.size()) << file;
  const auto interior = interior_fraction(labels);
  const double voxel = labels.grid.voxel_volume();
  double mesh = 0, voxels = 0;
  for (const auto& [label, t] : totals) {
    EXPECT_EQ(t.parts, expected[label]) << file << " label " << label;
    // A surface at 0.5 cuts the staircase's corners: labels one or two voxels thick lose 5-20 %
    // of their voxel volume (VTK's discrete flying edges loses the same on the same labels,
    // docs/STUDY.md), so the 5 % bound holds for labels whose voxels are mostly interior. Specks
    // of a few voxels (a single voxel meshes to an octahedron of 1/6 its volume) are only checked
    // for closedness above.
    const double bound = interior.at(label) >= 0.5 ? 0.05 : t.voxel_volume >= 27 * voxel ? 0.25 : 1.0;
    EXPECT_NEAR(t.mesh_volume, t.voxel_volume, bound * t.voxel_volume)
        << file << " label " << label << " (interior fraction " << interior.at(label) << ")";
    mesh += t.mesh_volume;
    voxels += t.voxel_volume;
  }
  EXPECT_NEAR(mesh, voxels, 0.02 * voxels) << file << ": all labels together";
}

TEST(RealData, TotalSegmentatorExampleEveryLabel) {
  SEGMESH_DATA_FILE(file, "totalsegmentator/example_seg.nii.gz");
  for (Method method : {Method::marching_cubes, Method::dual_contouring}) {
    check_label_map(file, 26, method);
  }
}

TEST(RealData, TotalSegmentatorAnisotropicEveryLabelAllConnectivities) {
  SEGMESH_DATA_FILE(file, "totalsegmentator/example_seg_dicom.nii.gz");
  for (Method method : {Method::marching_cubes, Method::dual_contouring}) {
    for (int connectivity : {26, 18, 6}) check_label_map(file, connectivity, method);
  }
}

TEST(RealData, PelvicFractureFragments) {
  for (const char* bone : {"001_LI_mask.nii.gz", "001_RI_mask.nii.gz", "001_SA_mask.nii.gz"}) {
    SEGMESH_DATA_FILE(file, std::string("pelvic_fracture/001/") + bone);
    for (Method method : {Method::marching_cubes, Method::dual_contouring}) {
      check_label_map(file, 26, method);
    }
  }
}

// Conforming surfaces (the default) on real maps whose parts touch, from both extractors: every
// part closed and manifold, every contact shared to float rounding after the default smoothing and
// no triangle of one part passing through another part's (measured before the fold repair: 81 crossing triangles on case 001, 523 on the 3 mm
// TotalSegmentator map; bench/compare_conforming_vtk.sh).
TEST(RealData, TouchingPartsShareTheirContactsAndNeverCross) {
  for (const char* name : {"pelvic_fracture/001/001_LI_mask.nii.gz",
                           "totalsegmentator/example_seg.nii.gz",
                           "totalsegmentator/example_seg_dicom.nii.gz"}) {
    SEGMESH_DATA_FILE(file, name);
    const Image image = read_volume(file);
    for (Method method : {Method::marching_cubes, Method::dual_contouring}) {
      const std::string what = std::string(name) + " " + std::string(method_name(method));
      const Scene scene =
          build_scene(image, {.method = method, .surfaces = Surfaces::conforming});
      ASSERT_TRUE(scene.surface.has_value()) << what << ": its parts touch";
      for (const Part& part : scene.parts) {
        const MeshMeasures m = measure_mesh(part.mesh);
        expect_closed_manifold(m, what + " " + part.name);
        EXPECT_GT(m.volume_mm3, 0) << what << " " << part.name;
      }
      const SceneMeasures m = measure_scene(scene, {});
      ASSERT_FALSE(m.contacts.empty()) << what;
      for (const ContactMeasures& c : m.contacts) {
        const Part& a = scene.parts[c.a];
        const Part& b = scene.parts[c.b];
        EXPECT_LT(c.max_gap_mm, 1e-4) << what << ": " << a.name << " " << b.name;
        EXPECT_EQ(test::crossings(a.mesh, b.mesh), 0u) << what << ": " << a.name << " " << b.name;
      }
    }
  }
}

// Triangle-weighted mean radii ratio over a scene's parts.
double mean_radii_ratio(const Scene& scene) {
  double sum = 0, n = 0;
  for (const Part& part : scene.parts) {
    const QualityStats q = triangle_quality(part.mesh);
    sum += q.mean * double(q.triangles);
    n += double(q.triangles);
  }
  return n > 0 ? sum / n : 0;
}

TEST(RealData, DualContouringHasBetterTrianglesThanMarchingCubes) {
  for (const char* name : {"pelvic_fracture/001/001_LI_mask.nii.gz", "totalsegmentator/example_seg_dicom.nii.gz"}) {
    SEGMESH_DATA_FILE(file, name);
    const Image image = read_volume(file);
    double mean[2];
    for (Method method : {Method::marching_cubes, Method::dual_contouring}) {
      mean[method == Method::dual_contouring] =
          mean_radii_ratio(build_scene(image, {.method = method}));
    }
    EXPECT_GT(mean[1], mean[0]) << name << ": mean radii ratio DC " << mean[1] << ", MC " << mean[0];
  }
}

// The label maps of ../shared/data (README.md). Those of the tests above, whose part counts and
// volumes are checked too, and every other one segmesh reads.
const std::vector<std::string> kCheckedLabelMaps = {
    "totalsegmentator/example_seg.nii.gz", "totalsegmentator/example_seg_dicom.nii.gz",
    "pelvic_fracture/001/001_LI_mask.nii.gz", "pelvic_fracture/001/001_RI_mask.nii.gz",
    "pelvic_fracture/001/001_SA_mask.nii.gz"};
const std::vector<std::string> kOtherLabelMaps = {"pelvic_fracture/002/002_LI_mask.nii.gz",
                                                  "pelvic_fracture/002/002_RI_mask.nii.gz",
                                                  "pelvic_fracture/002/002_SA_mask.nii.gz",
                                                  "pelvic_fracture/003/003_LI_mask.nii.gz",
                                                  "pelvic_fracture/003/003_RI_mask.nii.gz",
                                                  "pelvic_fracture/003/003_SA_mask.nii.gz",
                                                  "dcmqi/liver_spine_seg.nrrd",
                                                  "dcmqi/heart_seg.nrrd",
                                                  "dcmqi/liver_seg.nrrd",
                                                  "dcmqi/spine_seg.nrrd",
                                                  "dcmqi/spine_seg_label5.nrrd"};
// Volume files of the data that are grey values, not label maps (CT in HU, MRC density maps).
const std::vector<std::string> kGreyValueVolumes = {
    "totalsegmentator/example_ct_sm.nii.gz", "totalsegmentator/example_ct.nii.gz",
    "pelvic_fracture/001/001_LI.nii.gz", "mrc/EMD-3197.map", "mrc/EMD-3001.map"};
// DICOM SEG objects (single .dcm files, which the extension scan below cannot tell from the
// slices of a series): meshed with the other label maps.
const std::vector<std::string> kDicomSegLabelMaps = {"dcmqi/liver.dcm",
                                                     "dcmqi/partial_overlaps.dcm"};

bool listed(const std::vector<std::string>& list, const std::string& name) {
  return std::find(list.begin(), list.end(), name) != list.end();
}

// Every volume file of the data is one of the lists above, so a label map added to the data (or a
// list entry that lost its file) is noticed here instead of going unmeshed.
TEST(RealData, EveryVolumeFileInTheDataIsListed) {
  if (test::shared_data_dir().empty()) GTEST_SKIP() << "../shared/data not found";
  const std::filesystem::path root = test::shared_data_dir();
  int volumes = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
    if (!entry.is_regular_file()) continue;
    const std::string name = entry.path().lexically_relative(root).generic_string();
    const std::string file = entry.path().filename().string();
    auto ends = [&](const std::string& suffix) {
      return file.size() >= suffix.size() &&
             file.compare(file.size() - suffix.size(), suffix.size(), suffix) == 0;
    };
    const bool volume = ends(".nii") || ends(".nii.gz") || ends(".nrrd") || ends(".nhdr") ||
                        ends(".mha") || ends(".mhd") || ends(".mrc") || ends(".map");
    if (!volume) continue;
    ++volumes;
    EXPECT_TRUE(listed(kCheckedLabelMaps, name) || listed(kOtherLabelMaps, name) ||
                listed(kGreyValueVolumes, name))
        << name
        << ": a volume file no list of test_real_data.cpp names (label map or grey values?)";
  }
  EXPECT_EQ(size_t(volumes),
            kCheckedLabelMaps.size() + kOtherLabelMaps.size() + kGreyValueVolumes.size())
      << "a listed volume file is missing from " << root;
  for (const std::string& name : kDicomSegLabelMaps) EXPECT_TRUE(std::filesystem::exists(root / name)) << name;
}

// Every label map not checked above: every label meshed (its parts against the breadth-first
// count) by both methods, every part closed and manifold (edges and vertices), no degenerate
// triangles, positive volume.
TEST(RealData, EveryOtherLabelMapInTheDataClosedAndManifoldWithBothMethods) {
  std::vector<std::string> maps = kOtherLabelMaps;
  maps.insert(maps.end(), kDicomSegLabelMaps.begin(), kDicomSegLabelMaps.end());
  for (const std::string& name : maps) {
    SEGMESH_DATA_FILE(file, name);
    const Image image = read_volume(file);
    const auto expected = reference_parts(image.labels_int32(), 26);
    ASSERT_FALSE(expected.empty()) << name << ": no labels";
    for (Method method : {Method::marching_cubes, Method::dual_contouring}) {
      const std::string what = name + " " + std::string(method_name(method));
      const Scene scene = build_scene(image, {.method = method});
      std::map<int32_t, int64_t> parts;
      for (const Part& part : scene.parts) {
        const MeshMeasures m = measure_mesh(part.mesh);
        expect_closed_manifold(m, what + " " + part.name);
        EXPECT_EQ(m.degenerate_triangles, 0) << what << " " << part.name;
        EXPECT_GT(m.volume_mm3, 0) << what << " " << part.name;
        ++parts[part.label];
      }
      EXPECT_EQ(parts, expected) << what << ": parts per label (every label, every component)";
    }
  }
}

// As extracted, without smoothing: Dual Contouring's vertices (one per sheet of a cell, inside it)
// give better-shaped triangles than Marching Cubes' vertices at the edge midpoints of binary
// labels. Returns the number of parts of each method's scene (MC, DC).
std::array<size_t, 2> expect_raw_dc_better(const Image& image, const std::string& what) {
  MeshingOptions options;
  options.smooth.method = SmoothMethod::none;
  double mean[2];
  std::array<size_t, 2> parts{};
  for (Method method : {Method::marching_cubes, Method::dual_contouring}) {
    options.method = method;
    const Scene scene = build_scene(image, options);
    mean[method == Method::dual_contouring] = mean_radii_ratio(scene);
    parts[method == Method::dual_contouring] = scene.parts.size();
  }
  EXPECT_GT(mean[1], mean[0]) << what << ", raw extraction: mean radii ratio DC " << mean[1]
                              << ", MC " << mean[0];
  ::testing::Test::RecordProperty("raw_mean_rho_mc " + what, std::to_string(mean[0]));
  ::testing::Test::RecordProperty("raw_mean_rho_dc " + what, std::to_string(mean[1]));
  return parts;
}

TEST(RealData, RawDualContouringHasBetterTrianglesThanRawMarchingCubesOnThePhantom) {
  Image phantom;
  phantom.path = "phantom 256x256x102 at 0.394x0.394x4 mm";
  phantom.voxel_type = "int32";
  phantom.volume = make_phantom({.size = {256, 256, 102}, .spacing = {0.394, 0.394, 4.0}});
  const auto parts = expect_raw_dc_better(phantom, phantom.path);
  // phantom.hpp: two tibia fragments and the fibula, the plate and six screws.
  EXPECT_EQ(parts[0], 10u) << phantom.path << ": Marching Cubes parts";
  EXPECT_EQ(parts[1], 10u) << phantom.path << ": Dual Contouring parts";
}

TEST(RealData, RawDualContouringHasBetterTrianglesThanRawMarchingCubesOnEveryLabelMap) {
  std::vector<std::string> all = kCheckedLabelMaps;
  all.insert(all.end(), kOtherLabelMaps.begin(), kOtherLabelMaps.end());
  for (const std::string& name : all) {
    SEGMESH_DATA_FILE(file, name);
    expect_raw_dc_better(read_volume(file), name);
  }
}

TEST(RealData, GreyValueCtAtIntegerIsoIsClosedWithoutDegenerateTriangles) {
  // Integer HU at an integer iso: corner values equal the iso value (VTK's marching cubes gave
  // non-manifold edges and scikit-image degenerate triangles here).
  SEGMESH_DATA_FILE(file, "totalsegmentator/example_ct.nii.gz");
  const Image image = read_volume(file);
  for (Method method : {Method::marching_cubes, Method::dual_contouring}) {
    const Scene scene = build_scene(image, {.method = method, .iso = 200, .min_voxels = 10});
    ASSERT_FALSE(scene.parts.empty());
    for (const Part& part : scene.parts) {
      const MeshMeasures m = measure_mesh(part.mesh);
      expect_closed_manifold(m,
                             image.path + " " + part.name + " " + std::string(method_name(method)));
      EXPECT_EQ(m.degenerate_triangles, 0) << part.name << " " << method_name(method);
    }
  }
}

TEST(RealData, PelvicCtCropAtIso) {
  SEGMESH_DATA_FILE(file, "pelvic_fracture/001/001_LI.nii.gz");
  const Image image = read_volume(file);
  const Scene scene = build_scene(image, {.iso = 150, .normals = NormalMethod::sobel});
  ASSERT_FALSE(scene.parts.empty());
  for (const Part& part : scene.parts)
    expect_closed_manifold(measure_mesh(part.mesh), image.path + " " + part.name);
}

TEST(RealData, SameScenesForOneAndTwoThreads) {
  SEGMESH_DATA_FILE(file, "pelvic_fracture/001/001_SA_mask.nii.gz");
  const Image image = read_volume(file);
  Scene one, two;
  tbb::task_arena(1).execute([&] { one = build_scene(image, {}); });
  tbb::task_arena(2).execute([&] { two = build_scene(image, {}); });
  ASSERT_EQ(one.parts.size(), two.parts.size());
  for (size_t p = 0; p < one.parts.size(); ++p) {
    const TriMesh& a = one.parts[p].mesh;
    const TriMesh& b = two.parts[p].mesh;
    EXPECT_EQ(a.indices, b.indices);
    ASSERT_EQ(a.positions.size(), b.positions.size());
    EXPECT_EQ(0, std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(Vec3f)));
  }
}

}  // namespace
}  // namespace segmesh
