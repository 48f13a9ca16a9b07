#include "segmesh_io/detail/text.hpp"

#include <algorithm>

namespace segmesh {

std::string_view trim(std::string_view text, std::string_view blanks) {
  const auto first = text.find_first_not_of(blanks);
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(blanks);
  return text.substr(first, last - first + 1);
}

std::string_view trim_end(std::string_view text, std::string_view blanks) {
  const auto last = text.find_last_not_of(blanks);
  return last == std::string_view::npos ? std::string_view() : text.substr(0, last + 1);
}

std::string lower(std::string text) {
  for (char& c : text) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  }
  return text;
}

std::string_view next_word(std::string_view& s) {
  s = trim(s, kWhiteSpace);
  const size_t n = std::min(s.find_first_of(kWhiteSpace), s.size());
  const std::string_view word = s.substr(0, n);
  s.remove_prefix(n);
  return word;
}

}  // namespace segmesh
