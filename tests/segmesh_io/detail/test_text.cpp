// Text helpers (text.hpp): trimming with the default and other blank sets, ASCII-only lower
// case, whitespace-separated words, whole-token numbers.
#include <gtest/gtest.h>

#include <cstdint>
#include <set>
#include <string>
#include <string_view>

#include "segmesh_io/detail/text.hpp"

namespace segmesh {
namespace {

using namespace std::literals;

TEST(Text, TrimsTheGivenBlanks) {
  EXPECT_EQ(trim(" \tgzip \r\n"), "gzip");
  EXPECT_EQ(trim(" \t\r\n"), "");
  EXPECT_EQ(trim(""), "");
  EXPECT_EQ(trim("\va b\f"), "\va b\f");  // not header blanks
  EXPECT_EQ(trim("\va b\f", kWhiteSpace), "a b");
  EXPECT_EQ(trim_end("1.2.840.10008.1.2\0"sv, "\0 "sv), "1.2.840.10008.1.2");
  EXPECT_EQ(trim_end(" 1.2 \0 "sv, "\0 "sv), " 1.2");
  EXPECT_EQ(trim_end("\0\0"sv, "\0 "sv), "");
}

TEST(Text, LowerCaseIsAsciiOnly) {
  EXPECT_EQ(lower("Big.NII.GZ"), "big.nii.gz");
  EXPECT_EQ(lower("\xc3\x89t\xc3\xa9"), "\xc3\x89t\xc3\xa9");  // UTF-8 bytes are kept
}

TEST(Text, NextWordTakesOneWordAtATime) {
  std::string_view s = "  f 1//1\t2//2 \r";
  EXPECT_EQ(next_word(s), "f");
  EXPECT_EQ(next_word(s), "1//1");
  EXPECT_EQ(next_word(s), "2//2");
  EXPECT_EQ(next_word(s), "");
  EXPECT_TRUE(s.empty());
}

TEST(Text, NumbersMustFillTheToken) {
  int32_t i = 0;
  EXPECT_TRUE(parse_number("+12", i));
  EXPECT_EQ(i, 12);
  EXPECT_TRUE(parse_number("-3", i));
  EXPECT_EQ(i, -3);
  EXPECT_FALSE(parse_number("12x", i));
  EXPECT_FALSE(parse_number("", i));
  EXPECT_FALSE(parse_number("+", i));
  float f = 0;
  EXPECT_TRUE(parse_number("0.5e1", f));
  EXPECT_EQ(f, 5.0f);
  uint64_t u = 0;
  EXPECT_FALSE(parse_number("-1", u));
}

// Unique names: the first of a name as it is, then _2, _3, ...; a given name that is taken skips
// its suffix; case folded or not; many equal names (the parts of a many-part scene) stay distinct.
TEST(Text, UniqueNamesCountOnAndFoldCaseWhenAsked) {
  UniqueNames files(/*fold_case=*/true);
  EXPECT_EQ(files.make("femur"), "femur");
  EXPECT_EQ(files.make("Femur"), "Femur_2");
  EXPECT_EQ(files.make("femur_3"), "femur_3");
  EXPECT_EQ(files.make("femur"), "femur_4");
  EXPECT_EQ(files.make("femur_2"), "femur_2_2");
  UniqueNames materials(/*fold_case=*/false);
  EXPECT_EQ(materials.make("femur"), "femur");
  EXPECT_EQ(materials.make("Femur"), "Femur");
  EXPECT_EQ(materials.make("femur"), "femur_2");
  UniqueNames many(true);
  std::set<std::string> seen;
  for (int i = 0; i < 100000; ++i) seen.insert(many.make("part"));
  EXPECT_EQ(seen.size(), 100000u);
  EXPECT_TRUE(seen.contains("part_100000"));
}

}  // namespace
}  // namespace segmesh
