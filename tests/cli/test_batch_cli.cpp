// `segmesh batch` end to end (issue 38): failure isolation (a corrupt and a missing case fail, the
// rest mesh), resume (finished cases skipped, failed ones retried, --force redoes), shards that
// together cover every case once, stale temporary folders cleaned and never taken for done,
// detached data outside a header's folder refused unless --allow-external-data, per-case options
// from a manifest, and bad arguments refused with nothing written. Inputs are the small label
// maps of ../shared/data (each meshes in well under a second).
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli/cli_run.hpp"
#include "segmesh_io/volume_test_support.hpp"
#include "support/test_support.hpp"

namespace segmesh {
namespace {

namespace fs = std::filesystem;
using test::run_segmesh;
using test::shell_quoted;

using Row = std::map<std::string, std::string>;

// The rows of a summary CSV by column name (RFC 4180 quotes; no line breaks inside fields).
std::vector<Row> read_summary(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> columns;
  std::vector<Row> rows;
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> fields(1);
    bool quoted = false;
    for (size_t i = 0; i < line.size(); ++i) {
      const char c = line[i];
      if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = !quoted;
      } else if (c == ',' && !quoted) {
        fields.emplace_back();
      } else {
        fields.back() += c;
      }
    }
    if (columns.empty()) {
      columns = fields;
      continue;
    }
    Row row;
    for (size_t i = 0; i < columns.size() && i < fields.size(); ++i) row[columns[i]] = fields[i];
    rows.push_back(row);
  }
  return rows;
}

Row row_of(const std::vector<Row>& rows, const std::string& name) {
  for (const Row& r : rows) {
    if (r.at("case") == name) return r;
  }
  ADD_FAILURE() << "no row for case " << name;
  return {};
}

// Hidden entries (temporary case folders) left in `out`.
std::vector<std::string> hidden_entries(const fs::path& out) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(out)) {
    if (e.path().filename().string().front() == '.') names.push_back(e.path().filename().string());
  }
  return names;
}

nlohmann::json read_json(const fs::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in);
}

fs::file_time_type mtime(const fs::path& p) { return fs::last_write_time(p); }

// Four small real label maps, a corrupt file and a missing one; the corrupt file is made valid
// before the second run, which must skip the four finished cases, retry the two failed ones (one
// now meshes) and leave the finished folders untouched; --force redoes every case.
TEST(BatchCli, FailedCasesAreIsolatedAndASecondRunSkipsFinishedOnes) {
  SEGMESH_DATA_FILE(heart, "dcmqi/heart_seg.nrrd");
  SEGMESH_DATA_FILE(spine, "dcmqi/spine_seg.nrrd");
  SEGMESH_DATA_FILE(liver_spine, "dcmqi/liver_spine_seg.nrrd");
  SEGMESH_DATA_FILE(total, "totalsegmentator/example_seg.nii.gz");
  const fs::path dir = test::scratch_dir("batch_isolation");
  const fs::path corrupt = dir / "corrupt.nrrd";
  volume_test::write_text(corrupt, "not a volume at all, only text pretending to be NRRD\n");
  const fs::path out = dir / "out";
  const std::string inputs = shell_quoted(heart) + " " + shell_quoted(spine) + " " +
                             shell_quoted(corrupt) + " " + shell_quoted(liver_spine) + " " +
                             shell_quoted(dir / "missing.nii.gz") + " " + shell_quoted(total);
  const auto first = run_segmesh("batch " + inputs + " -o " + shell_quoted(out));
  EXPECT_EQ(first.exit_code, 1) << first.err;
  EXPECT_NE(first.err.find("[6/6] example_seg ok"), std::string::npos) << first.err;
  std::vector<Row> rows = read_summary(out / "summary.csv");
  ASSERT_EQ(rows.size(), 6u);
  const std::vector<std::string> order = {"heart_seg", "spine_seg", "corrupt",
                                          "liver_spine_seg", "missing", "example_seg"};
  for (size_t i = 0; i < rows.size(); ++i) EXPECT_EQ(rows[i].at("case"), order[i]);
  std::map<std::string, std::string> triangles;
  for (const Row& r : rows) {
    SCOPED_TRACE(r.at("case"));
    const bool fails = r.at("case") == "corrupt" || r.at("case") == "missing";
    EXPECT_EQ(r.at("status"), fails ? "failed" : "ok");
    EXPECT_EQ(fs::exists(out / r.at("case")), !fails);
    if (fails) continue;
    EXPECT_TRUE(r.at("error").empty());
    EXPECT_GT(std::stol(r.at("parts")), 0);
    EXPECT_GT(std::stol(r.at("triangles")), 0);
    EXPECT_GT(std::stod(r.at("volume_mm3")), 0);
    triangles[r.at("case")] = r.at("triangles");
    const nlohmann::json report = read_json(out / r.at("case") / "report.json");
    EXPECT_EQ(report["totals"]["triangles"].get<int64_t>(), std::stol(r.at("triangles")));
    EXPECT_EQ(report["outputs"][0], (out / r.at("case") / "scene.glb").string());
    EXPECT_TRUE(fs::exists(out / r.at("case") / "scene.glb"));
    EXPECT_TRUE(fs::exists(out / r.at("case") / "case.json"));
  }
  EXPECT_NE(row_of(rows, "corrupt").at("error").find("corrupt.nrrd: not a NRRD file"),
            std::string::npos);
  EXPECT_NE(row_of(rows, "missing").at("error").find("missing.nii.gz: no such file"),
            std::string::npos);
  EXPECT_TRUE(hidden_entries(out).empty());

  const auto heart_time = mtime(out / "heart_seg" / "scene.glb");
  fs::copy_file(heart, corrupt, fs::copy_options::overwrite_existing);
  const auto second = run_segmesh("batch " + inputs + " -o " + shell_quoted(out));
  EXPECT_EQ(second.exit_code, 1) << second.err;  // missing is still missing
  rows = read_summary(out / "summary.csv");
  ASSERT_EQ(rows.size(), 6u);
  for (const std::string name : {"heart_seg", "spine_seg", "liver_spine_seg", "example_seg"}) {
    EXPECT_EQ(row_of(rows, name).at("status"), "skipped") << name;
    EXPECT_EQ(row_of(rows, name).at("triangles"), triangles[name]) << name;
  }
  EXPECT_EQ(row_of(rows, "corrupt").at("status"), "ok");
  EXPECT_EQ(row_of(rows, "corrupt").at("triangles"), triangles["heart_seg"]);
  EXPECT_EQ(row_of(rows, "missing").at("status"), "failed");
  EXPECT_EQ(mtime(out / "heart_seg" / "scene.glb"), heart_time);

  const auto forced = run_segmesh("batch " + shell_quoted(heart) + " " + shell_quoted(spine) +
                                  " -o " + shell_quoted(out) + " --force --quiet");
  EXPECT_EQ(forced.exit_code, 0) << forced.err;
  EXPECT_TRUE(forced.err.empty()) << forced.err;
  rows = read_summary(out / "summary.csv");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].at("status"), "ok");
  EXPECT_EQ(rows[1].at("status"), "ok");
  EXPECT_EQ(rows[0].at("triangles"), triangles["heart_seg"]);
  EXPECT_NE(mtime(out / "heart_seg" / "scene.glb"), heart_time);
  EXPECT_TRUE(hidden_entries(out).empty());
}

// Issue 38's done-when, whole: every label map of ../shared/data (TotalSegmentator, the pelvic
// fracture masks, the dcmqi NRRDs: sixteen) plus a corrupt and a missing file, with the default
// options: exactly those two fail (exit code 1), and a second run skips every finished case.
TEST(BatchCli, EveryLabelMapOfTheSharedDataWithACorruptAndAMissingFile) {
  SEGMESH_DATA_FILE(data, "totalsegmentator/example_seg.nii.gz");
  const fs::path root = test::shared_data_dir();
  std::vector<fs::path> maps = {root / "totalsegmentator" / "example_seg.nii.gz",
                                root / "totalsegmentator" / "example_seg_dicom.nii.gz"};
  for (const char* c : {"001", "002", "003"})
    for (const char* bone : {"LI", "RI", "SA"})
      maps.push_back(root / "pelvic_fracture" / c / (std::string(c) + "_" + bone + "_mask.nii.gz"));
  for (const char* name : {"heart_seg", "liver_seg", "liver_spine_seg", "spine_seg", "spine_seg_label5"})
    maps.push_back(root / "dcmqi" / (std::string(name) + ".nrrd"));
  for (const fs::path& m : maps) ASSERT_TRUE(fs::exists(m)) << m;
  const fs::path dir = test::scratch_dir("batch_shared_data");
  volume_test::write_text(dir / "corrupt.nii.gz", "a NIfTI file in name only\n");
  std::string inputs;
  for (const fs::path& m : maps) inputs += shell_quoted(m) + " ";
  inputs += shell_quoted(dir / "corrupt.nii.gz") + " " + shell_quoted(dir / "missing.nrrd");
  const fs::path out = dir / "out";
  for (const char* run : {"first", "second"}) {
    SCOPED_TRACE(run);
    const auto r = run_segmesh("batch " + inputs + " -o " + shell_quoted(out) + " --quiet");
    EXPECT_EQ(r.exit_code, 1) << r.err;
    const std::vector<Row> rows = read_summary(out / "summary.csv");
    ASSERT_EQ(rows.size(), maps.size() + 2);
    const std::string done = std::string(run) == "first" ? "ok" : "skipped";
    for (size_t i = 0; i < maps.size(); ++i) {
      EXPECT_EQ(rows[i].at("status"), done) << rows[i].at("case") << ": " << rows[i].at("error");
      EXPECT_GT(std::stol(rows[i].at("parts")), 0) << rows[i].at("case");
    }
    EXPECT_EQ(rows[maps.size()].at("case"), "corrupt");
    EXPECT_EQ(rows[maps.size()].at("status"), "failed");
    EXPECT_EQ(rows[maps.size() + 1].at("case"), "missing");
    EXPECT_EQ(rows[maps.size() + 1].at("status"), "failed");
    EXPECT_TRUE(hidden_entries(out).empty());
  }
}

// --shard 1/3, 2/3, 3/3 into one folder: each writes its own summary, and together they take
// every case exactly once (names are given over the whole list, so "a_seg" and "b_seg" agree).
TEST(BatchCli, ShardsCoverEveryCaseExactlyOnce) {
  SEGMESH_DATA_FILE(heart, "dcmqi/heart_seg.nrrd");
  SEGMESH_DATA_FILE(spine, "dcmqi/spine_seg.nrrd");
  const fs::path dir = test::scratch_dir("batch_shards");
  fs::create_directories(dir / "a");
  fs::create_directories(dir / "b");
  fs::copy_file(heart, dir / "a" / "seg.nrrd");
  fs::copy_file(spine, dir / "b" / "seg.nrrd");
  // Seven cases; the missing ones fail at once, which is all a shard needs.
  const std::string inputs = shell_quoted(dir / "a") + " " + shell_quoted(dir / "b") + " " +
                             shell_quoted(dir / "gone1.nrrd") + " " + shell_quoted(dir / "gone2.nrrd") +
                             " " + shell_quoted(dir / "gone3.nrrd") + " " + shell_quoted(spine) +
                             " " + shell_quoted(dir / "gone4.nrrd");
  std::multiset<std::string> seen;
  for (int shard = 1; shard <= 3; ++shard) {
    const std::string s = std::to_string(shard) + "/3";
    const auto r = run_segmesh("batch " + inputs + " -o " + shell_quoted(dir / "out") +
                               " --quiet --shard " + s);
    EXPECT_EQ(r.exit_code, 1) << r.err;  // every shard holds a missing case
    const fs::path summary = dir / "out" / ("summary-" + std::to_string(shard) + "-of-3.csv");
    ASSERT_TRUE(fs::exists(summary)) << s;
    for (const Row& row : read_summary(summary)) seen.insert(row.at("case") + " " + row.at("input"));
  }
  EXPECT_FALSE(fs::exists(dir / "out" / "summary.csv"));
  const std::multiset<std::string> expected = {
      "a_seg " + (dir / "a" / "seg.nrrd").string(),
      "b_seg " + (dir / "b" / "seg.nrrd").string(),
      "gone1 " + (dir / "gone1.nrrd").string(),
      "gone2 " + (dir / "gone2.nrrd").string(),
      "gone3 " + (dir / "gone3.nrrd").string(),
      "spine_seg " + spine.string(),
      "gone4 " + (dir / "gone4.nrrd").string()};
  EXPECT_EQ(seen, expected);
  EXPECT_TRUE(fs::exists(dir / "out" / "a_seg" / "case.json"));
  EXPECT_TRUE(fs::exists(dir / "out" / "b_seg" / "case.json"));
}

// A cohort as segmenters write it, one folder per subject with files of one name, the output
// folder inside it: every volume below the folder is a case, named by its subject folder; a
// folder of notes is no DICOM series and no case; the output folder is never taken for input,
// so a second run finds the same cases, all finished.
TEST(BatchCli, CohortFolderIsSearchedWholeAndNamesCasesByTheirFolders) {
  SEGMESH_DATA_FILE(heart, "dcmqi/heart_seg.nrrd");
  SEGMESH_DATA_FILE(spine, "dcmqi/spine_seg.nrrd");
  const fs::path dir = test::scratch_dir("batch_tree");
  const fs::path cohort = dir / "cohort";
  fs::create_directories(cohort / "s0001" / "segmentations");
  fs::create_directories(cohort / "s0002" / "segmentations");
  fs::create_directories(cohort / "notes");
  fs::copy_file(heart, cohort / "s0001" / "segmentations" / "seg.nrrd");
  fs::copy_file(spine, cohort / "s0002" / "segmentations" / "seg.nrrd");
  fs::copy_file(spine, cohort / "s0002" / "spine.nrrd");
  volume_test::write_text(cohort / "notes" / "readme.txt", "who segmented what\n");
  const fs::path out = cohort / "meshes";
  for (const char* run : {"first", "second"}) {
    SCOPED_TRACE(run);
    const auto r = run_segmesh("batch " + shell_quoted(cohort) + " -o " + shell_quoted(out));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    const std::vector<Row> rows = read_summary(out / "summary.csv");
    ASSERT_EQ(rows.size(), 3u);
    const std::string status = std::string(run) == "first" ? "ok" : "skipped";
    EXPECT_EQ(rows[0].at("case"), "s0001_segmentations_seg");
    EXPECT_EQ(rows[1].at("case"), "s0002_segmentations_seg");
    EXPECT_EQ(rows[2].at("case"), "spine");
    for (const Row& row : rows) EXPECT_EQ(row.at("status"), status) << row.at("case");
  }
  // A leaf folder holding only DICOM-looking files is a series (here an unreadable one: a
  // failed case, named by its folder); the notes folder still is none.
  fs::create_directories(cohort / "s0003" / "dicom");
  std::string fake(128, '\0');
  fake += "DICMnot really";
  volume_test::write_text(cohort / "s0003" / "dicom" / "IM0001", fake);
  const auto r = run_segmesh("batch " + shell_quoted(cohort) + " -o " + shell_quoted(out));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  const std::vector<Row> rows = read_summary(out / "summary.csv");
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[3].at("case"), "dicom");
  EXPECT_EQ(rows[3].at("status"), "failed");
}

// What a killed run leaves (a hidden temporary folder, even one holding a marker; an old folder
// a forced run had set aside) is removed and never taken for a finished case; a case folder
// without its marker is redone and replaced.
TEST(BatchCli, StaleTemporaryFoldersAreCleanedAndNeverCountAsDone) {
  SEGMESH_DATA_FILE(heart, "dcmqi/heart_seg.nrrd");
  SEGMESH_DATA_FILE(spine, "dcmqi/spine_seg.nrrd");
  const fs::path out = test::scratch_dir("batch_stale") / "out";
  fs::create_directories(out / ".heart_seg.tmp-999999");
  volume_test::write_text(out / ".heart_seg.tmp-999999" / "case.json",
                          R"({"status": "ok", "input": ")" + heart.string() +
                              R"(", "parts": 1, "triangles": 1, "volume_mm3": 1, "seconds": 1})");
  fs::create_directories(out / ".heart_seg.old-999998");
  fs::create_directories(out / "spine_seg");
  volume_test::write_text(out / "spine_seg" / "scene.glb", "half written");
  const auto r = run_segmesh("batch " + shell_quoted(heart) + " " + shell_quoted(spine) + " -o " +
                             shell_quoted(out) + " --quiet");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  const std::vector<Row> rows = read_summary(out / "summary.csv");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].at("status"), "ok");
  EXPECT_GT(std::stol(rows[0].at("triangles")), 1);
  EXPECT_EQ(rows[1].at("status"), "ok");
  EXPECT_GT(fs::file_size(out / "spine_seg" / "scene.glb"), 1000u);
  EXPECT_TRUE(fs::exists(out / "spine_seg" / "case.json"));
  EXPECT_TRUE(hidden_entries(out).empty());
}

// A detached NRRD header whose data file lies outside its folder: refused in a batch (the case
// fails naming --allow-external-data), read with the flag.
TEST(BatchCli, ExternalDataFailsUnlessAllowed) {
  const fs::path dir = test::scratch_dir("batch_external");
  fs::create_directories(dir / "case");
  volume_test::Bytes voxels(6 * 5 * 4, 0);
  for (int z = 1; z < 3; ++z)
    for (int y = 1; y < 4; ++y)
      for (int x = 1; x < 5; ++x) voxels[(z * 5 + y) * 6 + x] = 1;
  volume_test::write_bytes(dir / "outside.raw", voxels);
  volume_test::write_text(dir / "case" / "up.nhdr",
                          "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 6 5 4\n"
                          "spacings: 1 1 1\nencoding: raw\ndata file: ../outside.raw\n");
  const std::string args = "batch " + shell_quoted(dir / "case" / "up.nhdr") + " -o " +
                           shell_quoted(dir / "out") + " --quiet";
  const auto refused = run_segmesh(args);
  EXPECT_EQ(refused.exit_code, 1) << refused.err;
  Row row = read_summary(dir / "out" / "summary.csv").at(0);
  EXPECT_EQ(row.at("status"), "failed");
  EXPECT_NE(row.at("error").find("up.nhdr: its data file"), std::string::npos) << row.at("error");
  EXPECT_NE(row.at("error").find("--allow-external-data"), std::string::npos) << row.at("error");
  EXPECT_FALSE(fs::exists(dir / "out" / "up"));
  const auto allowed = run_segmesh(args + " --allow-external-data");
  EXPECT_EQ(allowed.exit_code, 0) << allowed.err;
  row = read_summary(dir / "out" / "summary.csv").at(0);
  EXPECT_EQ(row.at("status"), "ok");
  EXPECT_EQ(row.at("parts"), "1");
}

// A manifest: paths relative to it, per-case options through the options layer (a quoted label
// list, a flag, an option by its underscore name), the command line's options as defaults, a
// `case` column; the same file twice gets two names. --labels 2 keeps only the spine's parts.
TEST(BatchCli, ManifestGivesPerCaseOptions) {
  SEGMESH_DATA_FILE(liver_spine, "dcmqi/liver_spine_seg.nrrd");
  const fs::path dir = test::scratch_dir("batch_manifest");
  fs::copy_file(liver_spine, dir / "ls.nrrd");
  volume_test::write_text(dir / "cohort.csv",
                          "path,labels,min_voxels,case\n"
                          "ls.nrrd,,,\n"
                          "ls.nrrd,2,,\n"
                          "ls.nrrd,\"1,2\",100,big\n");
  const auto r = run_segmesh("batch " + shell_quoted(dir / "cohort.csv") + " -o " +
                             shell_quoted(dir / "out") + " --quiet --smooth none");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<Row> rows = read_summary(dir / "out" / "summary.csv");
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].at("case"), "ls");
  EXPECT_EQ(rows[1].at("case"), "ls_2");
  EXPECT_EQ(rows[2].at("case"), "big");
  EXPECT_EQ(rows[0].at("input"), (dir / "ls.nrrd").string());
  const nlohmann::json all = read_json(dir / "out" / "ls" / "report.json");
  const nlohmann::json spine = read_json(dir / "out" / "ls_2" / "report.json");
  const nlohmann::json big = read_json(dir / "out" / "big" / "report.json");
  EXPECT_EQ(all["options"]["smooth"]["method"], "none");  // the command line's default
  EXPECT_EQ(spine["options"]["labels"], nlohmann::json({2}));
  size_t spine_parts = 0, big_parts = 0;
  for (const auto& part : all["parts"]) {
    spine_parts += part["label"] == 2;
    big_parts += part["voxels"].get<int64_t>() >= 100;
  }
  EXPECT_GT(spine_parts, 0u);
  EXPECT_LT(spine_parts, all["parts"].size());
  EXPECT_EQ(std::stoul(rows[1].at("parts")), spine_parts);
  EXPECT_EQ(std::stoul(rows[2].at("parts")), big_parts);
  for (const auto& part : spine["parts"]) EXPECT_EQ(part["label"], 2);
}

// Bad arguments: one line, exit 2, nothing written (not even the output folder); a quoted glob is
// expanded by batch itself; --help lists the batch options.
TEST(BatchCli, BadArgumentsWriteNothingAndGlobsExpand) {
  SEGMESH_DATA_FILE(spine, "dcmqi/spine_seg.nrrd");
  const fs::path dir = test::scratch_dir("batch_arguments");
  fs::copy_file(spine, dir / "one.nrrd");
  fs::copy_file(spine, dir / "two.nrrd");
  volume_test::write_text(dir / "unknown.csv", "path,smoothness\none.nrrd,2\n");
  volume_test::write_text(dir / "badvalue.csv", "path,connectivity\none.nrrd,7\n");
  volume_test::write_text(dir / "nopath.tsv", "file\tlabels\none.nrrd\t1\n");
  const fs::path out = dir / "out";
  const std::vector<std::pair<std::string, std::string>> bad = {
      {shell_quoted(dir / "one.nrrd") + " --shard 4/3", "--shard must be I/N"},
      {shell_quoted(dir / "one.nrrd") + " --shard x", "--shard must be I/N"},
      {shell_quoted(dir / "one.nrrd") + " --format vrml", "--format must be"},
      {shell_quoted(dir / "one.nrrd") + " --smooth wobbly", "--smooth"},
      {shell_quoted(dir / "one.nrrd") + " --quantize --format ply", "--quantize"},
      {shell_quoted(dir / "unknown.csv"), "unknown.csv: unknown column \"smoothness\""},
      {shell_quoted(dir / "badvalue.csv"), "badvalue.csv:2: --connectivity must be 6, 18 or 26"},
      {shell_quoted(dir / "nopath.tsv"), "nopath.tsv: "},
      {"'" + (dir / "*.nii.gz").string() + "'", "matches no file"},
  };
  for (const auto& [args, message] : bad) {
    SCOPED_TRACE(args);
    const auto r = run_segmesh("batch " + args + " -o " + shell_quoted(out));
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
  const auto globbed = run_segmesh("batch '" + (dir / "*.nrrd").string() + "' -o " +
                                   shell_quoted(out.string() + "/") + " --quiet --format ply");
  EXPECT_EQ(globbed.exit_code, 0) << globbed.err;
  const std::vector<Row> rows = read_summary(out / "summary.csv");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].at("case"), "one");
  EXPECT_EQ(rows[1].at("case"), "two");
  EXPECT_TRUE(fs::exists(out / "one" / "scene.ply"));
  EXPECT_EQ(read_json(out / "one" / "report.json")["outputs"][0], (out / "one" / "scene.ply").string());
  const auto help = run_segmesh("batch --help");
  EXPECT_EQ(help.exit_code, 0);
  for (const char* option : {"--shard", "--force", "--allow-external-data", "--labels", "--quiet"}) {
    EXPECT_NE(help.out.find(option), std::string::npos) << option;
  }
}

}  // namespace
}  // namespace segmesh
