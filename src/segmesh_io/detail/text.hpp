// Text helpers for the header and mesh parsers: trimming, ASCII lower case, whitespace-separated
// words and whole-token numbers. Internal to segmesh_io.
//
// Why one place: the NRRD, MetaImage and label-name readers, the ITK error text, the OBJ and PLY
// readers and the DICOM check each had their own copy. Guarantees: byte-wise and locale-free
// (ASCII only; other bytes are kept as they are); views returned point into the argument.
// Cost: one pass over the text, no allocation except lower()'s result.
//
// In namespace segmesh so that the volume_io and mesh_io code and the public entry points find
// them unqualified.
#pragma once

#include <charconv>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <string_view>
#include <system_error>

namespace segmesh {

// Line-end and blank characters that header values are trimmed of.
inline constexpr std::string_view kBlanks = " \t\r\n";
// The characters std::isspace accepts in the C locale.
inline constexpr std::string_view kWhiteSpace = " \t\n\v\f\r";

// `text` without leading and trailing characters from `blanks`.
std::string_view trim(std::string_view text, std::string_view blanks = kBlanks);
// `text` without trailing characters from `blanks`.
std::string_view trim_end(std::string_view text, std::string_view blanks);

// `text` with A-Z turned into a-z.
std::string lower(std::string text);

// The first word of `s` (a run of non-white-space, kWhiteSpace), taking it and the white space
// before it off `s` (which is also trimmed at its end); empty when `s` holds no word.
std::string_view next_word(std::string_view& s);

// `name` as a file name's stem: characters other than ASCII letters, digits, '-', '_' and '.'
// become '_', leading and trailing dots are dropped, at most 100 characters; `empty_name` when
// nothing is left.
std::string file_stem_for(std::string_view name, std::string_view empty_name);

// Names made unique: make(base) is `base`, or `base_2`, `base_3`, ... the first not made before
// (compared in lower case when folding case, for file systems that ignore it). Each base
// remembers the suffix it reached, so n equal names cost O(n), not O(n^2) (a scene of many
// parts named alike).
class UniqueNames {
 public:
  explicit UniqueNames(bool fold_case) : fold_case_(fold_case) {}
  std::string make(const std::string& base);

 private:
  std::string key(const std::string& name) const { return fold_case_ ? lower(name) : name; }
  bool fold_case_;
  std::unordered_set<std::string> used_;
  std::unordered_map<std::string, int> next_;  // per base's key: the suffix to try next
};

// `stem`, or `stem_2`, `stem_3`, ... the first not made by `used` before, compared in lower case.
inline std::string unique_stem(const std::string& stem, UniqueNames& used) { return used.make(stem); }

// Parses the whole of `s` as a T (a leading '+' allowed); false, with `out` unspecified, when `s`
// is empty or holds anything else.
template <class T>
bool parse_number(std::string_view s, T& out) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  const auto r = std::from_chars(s.data(), s.data() + s.size(), out);
  return !s.empty() && r.ec == std::errc() && r.ptr == s.data() + s.size();
}

}  // namespace segmesh
