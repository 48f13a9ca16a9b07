// JSON text written straight into a string, for the writers whose output grows with the parts (the
// GLB writers' JSON chunk, the mesh report): no tree of values, no allocation per value, a few
// nanoseconds per member. Internal to segmesh_io; reading JSON stays with nlohmann.
//
// The text is what nlohmann's dump gives for the same values, in the order written: compact
// (indent < 0) or one member per line with `indent` spaces per level, "key": value, empty
// containers as {} and []. Strings are escaped as JSON requires ('"', '\\', control characters),
// UTF-8 is kept, and bytes that are not valid UTF-8 become U+FFFD (names may come from Latin-1
// file headers). Numbers: integers exactly; doubles in their shortest exact form with ".0" added
// to integral ones (2.0, 0.1, 1e-05), and null for NaN and infinities, as nlohmann writes them
// (nlohmann switches to exponents at 1e16, this at to_chars's choice: the same values).
//
// The caller writes a well-formed sequence (a key before every member's value, containers closed
// in order); it is checked only by the tests.
#pragma once

#include <concepts>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace segmesh::mesh_io {

// `text` as a quoted JSON string appended to `out`.
void append_json_string(std::string& out, std::string_view text);
// `value` as a JSON number (or null) appended to `out`.
void append_json_number(std::string& out, double value);

class JsonText {
 public:
  explicit JsonText(int indent = -1) : indent_(indent) {}

  JsonText& begin_object() { return open('{'); }
  JsonText& end_object() { return close('}'); }
  JsonText& begin_array() { return open('['); }
  JsonText& end_array() { return close(']'); }
  // The next member's key; its value follows.
  JsonText& key(std::string_view name);

  JsonText& value(std::string_view text) {
    before_value();
    append_json_string(out_, text);
    return *this;
  }
  JsonText& value(const char* text) { return value(std::string_view(text)); }
  JsonText& value(const std::string& text) { return value(std::string_view(text)); }
  JsonText& value(bool b) {
    before_value();
    out_ += b ? "true" : "false";
    return *this;
  }
  template <std::integral T>
    requires(!std::same_as<T, bool> && !std::same_as<T, char>)
  JsonText& value(T v) {
    before_value();
    append_integer(static_cast<std::conditional_t<std::is_signed_v<T>, int64_t, uint64_t>>(v));
    return *this;
  }
  JsonText& value(double v) {
    before_value();
    append_json_number(out_, v);
    return *this;
  }
  JsonText& value(float v) = delete;  // say which: the float's own double, or tidy(v)
  JsonText& null() {
    before_value();
    out_ += "null";
    return *this;
  }
  // A value given as JSON text, compact or indented from depth 0 (nlohmann's dump(indent)); its
  // lines are indented to the current depth.
  JsonText& raw(std::string_view json);

  // `key`, then `v`.
  template <class T>
  JsonText& member(std::string_view name, const T& v) {
    key(name);
    return value(v);
  }

  std::string& text() { return out_; }

 private:
  JsonText& open(char bracket);
  JsonText& close(char bracket);
  void before_value();
  void newline(size_t depth);
  void append_integer(int64_t v);
  void append_integer(uint64_t v);

  std::string out_;
  int indent_;
  std::vector<bool> empty_;  // per open container: nothing in it yet
  bool after_key_ = false;
};

}  // namespace segmesh::mesh_io
