// JsonText: the text nlohmann would write for the same values (compact and indented), strings
// escaped and repaired, numbers that read back exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "segmesh_io/detail/json_text.hpp"

namespace segmesh::mesh_io {
namespace {

using Json = nlohmann::ordered_json;

// The same document through JsonText and through nlohmann.
void write_sample(JsonText& j) {
  j.begin_object().member("name", "femur").member("count", size_t{3}).member("negative", -7);
  j.member("ratio", 0.1).member("whole", 2.0).member("tiny", 1e-5).member("flag", true);
  j.key("none").null();
  j.key("empty_object").begin_object().end_object();
  j.key("empty_array").begin_array().end_array();
  j.key("list").begin_array().value(1).value(2.5).begin_object().member("x", false).end_object().end_array();
  j.key("nested").begin_object().key("inner").begin_array().value("a").end_array().end_object();
  j.end_object();
}

Json sample_json() {
  Json j;
  j["name"] = "femur";
  j["count"] = 3;
  j["negative"] = -7;
  j["ratio"] = 0.1;
  j["whole"] = 2.0;
  j["tiny"] = 1e-5;
  j["flag"] = true;
  j["none"] = nullptr;
  j["empty_object"] = Json::object();
  j["empty_array"] = Json::array();
  j["list"] = Json::array({1, 2.5, Json{{"x", false}}});
  j["nested"] = Json{{"inner", Json::array({"a"})}};
  return j;
}

TEST(JsonTextTest, WritesWhatNlohmannWritesCompactAndIndented) {
  for (const int indent : {-1, 2, 4}) {
    SCOPED_TRACE(indent);
    JsonText j(indent);
    write_sample(j);
    EXPECT_EQ(j.text(), sample_json().dump(indent));
  }
}

TEST(JsonTextTest, RawValuesAreIndentedToTheirDepth) {
  const Json inner = {{"a", 1}, {"b", Json::array({1, 2})}};
  JsonText j(2);
  j.begin_object().key("outer").begin_object().key("inner").raw(inner.dump(2)).end_object().end_object();
  EXPECT_EQ(j.text(), Json({{"outer", {{"inner", inner}}}}).dump(2));
  EXPECT_EQ(Json::parse(j.text())["outer"]["inner"], inner);
}

TEST(JsonTextTest, StringsAreEscapedAndInvalidUtf8Replaced) {
  const std::string tricky = std::string("quote\" back\\ tab\t nl\n cr\r bell\x07 nul") + '\0' +
                             " slash/ \xc3\xa9 \xe2\x82\xac \xf0\x9f\xa6\xb4";
  std::string out;
  append_json_string(out, tricky);
  EXPECT_EQ(Json::parse(out).get<std::string>(), tricky);
  EXPECT_EQ(out, Json(tricky).dump());
  // Latin-1, a lone continuation byte, a truncated sequence, an overlong form, a surrogate.
  for (const auto& [bad, repaired] : std::vector<std::pair<std::string, std::string>>{
           {"f\xe9mur", "f\xef\xbf\xbdmur"},
           {"a\x80z", "a\xef\xbf\xbdz"},
           {"end\xe2\x82", "end\xef\xbf\xbd\xef\xbf\xbd"},
           {"\xc0\xaf", "\xef\xbf\xbd\xef\xbf\xbd"},
           {"\xed\xa0\x80", "\xef\xbf\xbd\xef\xbf\xbd\xef\xbf\xbd"}}) {
    std::string text;
    append_json_string(text, bad);
    EXPECT_EQ(Json::parse(text).get<std::string>(), repaired) << text;
  }
}

TEST(JsonTextTest, NumbersReadBackExactlyAndNonFiniteIsNull) {
  for (const double v : {0.0, -0.0, 1.0, -3.0, 0.1, 1.0 / 3, 1e-300, 6.02e23, 1e16, 123456789012345678.0,
                         std::numeric_limits<double>::max(), std::numeric_limits<double>::denorm_min(),
                         double(0.7f)}) {
    std::string text;
    append_json_number(text, v);
    const Json back = Json::parse(text);
    ASSERT_TRUE(back.is_number_float()) << text;  // "2.0", not "2": a double stays a double
    EXPECT_EQ(back.get<double>(), v) << text;
  }
  for (const double v : {std::nan(""), std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()}) {
    std::string text;
    append_json_number(text, v);
    EXPECT_EQ(text, "null");
  }
  JsonText j;
  j.begin_array().value(int64_t{-9223372036854775807 - 1}).value(uint64_t{18446744073709551615u}).value(uint32_t{7}).end_array();
  EXPECT_EQ(j.text(), "[-9223372036854775808,18446744073709551615,7]");
}

}  // namespace
}  // namespace segmesh::mesh_io
