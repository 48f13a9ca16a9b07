// read_label_names: the TotalSegmentator class list and malformed files.
#include <algorithm>

#include "segmesh_io/label_names.hpp"
#include "support/test_support.hpp"
#include "volume_test_support.hpp"

namespace segmesh {
namespace {

using volume_test::expect_error;
namespace fs = std::filesystem;

TEST(LabelNames, TotalSegmentatorClasses) {
  SEGMESH_DATA_FILE(path, "totalsegmentator/labels.tsv");
  const std::vector<LabelInfo> labels = read_label_names(path);
  ASSERT_EQ(labels.size(), 117u);
  EXPECT_EQ(labels.front().label, 1);
  EXPECT_EQ(labels.front().name, "spleen");
  EXPECT_EQ(labels.front().role, Role::other);
  const LabelInfo* sacrum = find_label_info(labels, 25);
  ASSERT_NE(sacrum, nullptr);
  EXPECT_EQ(sacrum->name, "sacrum");
  EXPECT_EQ(sacrum->role, Role::bone);
  EXPECT_EQ(find_label_info(labels, 116)->name, "sternum");
  EXPECT_EQ(find_label_info(labels, 116)->role, Role::bone);
  EXPECT_EQ(find_label_info(labels, 117)->role, Role::other);
  const auto bones = std::count_if(labels.begin(), labels.end(),
                                   [](const LabelInfo& l) { return l.role == Role::bone; });
  EXPECT_EQ(bones, 62);
  EXPECT_TRUE(
      std::all_of(labels.begin(), labels.end(), [](const LabelInfo& l) { return !l.color; }));
}

TEST(LabelNames, CommentsBlankLinesWindowsLineEndsAndOptionalRole) {
  const fs::path path = test::scratch_dir("label_names_format") / "names.tsv";
  volume_test::write_text(path,
                          "# planning labels\r\n"
                          "\r\n"
                          "1\tfemur\tBONE\r\n"
                          "2\tplate\timplant\r\n"
                          "  # indented comment\n"
                          "7\tleft kidney\n"
                          "-3\tmarker\tother\n");
  const std::vector<LabelInfo> labels = read_label_names(path);
  ASSERT_EQ(labels.size(), 4u);
  EXPECT_EQ(labels[0].name, "femur");
  EXPECT_EQ(labels[0].role, Role::bone);
  EXPECT_EQ(labels[1].role, Role::implant);
  EXPECT_EQ(labels[2].label, 7);
  EXPECT_EQ(labels[2].name, "left kidney");
  EXPECT_FALSE(labels[2].role);
  EXPECT_EQ(labels[3].label, -3);
}

TEST(LabelNamesErrors, MalformedLinesNameFileAndLine) {
  const fs::path dir = test::scratch_dir("label_names_errors");
  auto check = [&](const std::string& name, const std::string& text, const std::string& expected) {
    volume_test::write_text(dir / name, text);
    expect_error([&] { read_label_names(dir / name); }, {(dir / name).string() + expected});
  };
  check("not_a_number.tsv", "label\tname\n1\tspleen\nthree\tliver\n",
        ":3: \"three\" is not an integer label");
  check("no_name.tsv", "# c\n1\tspleen\n2\n", ":3: label 2 has no name");
  check("spaces.tsv", "1 spleen\n2 liver\n", ":1: fields must be separated by tabs");
  check("role.tsv", "1\tspleen\tbones\n",
        ":1: unknown role \"bones\"; expected bone, implant or other");
  check("fields.tsv", "1\tspleen\tother\tred\n", ":1: too many fields (4)");
  check("twice.tsv", "1\tspleen\n2\tliver\n1\tkidney\n", ":3: label 1 is already named on line 1");
  check("empty.tsv", "# nothing\n", ": no label names found");
  expect_error([&] { read_label_names(dir / "missing.tsv"); },
               {(dir / "missing.tsv").string() + ": no such file"});
}

}  // namespace
}  // namespace segmesh
