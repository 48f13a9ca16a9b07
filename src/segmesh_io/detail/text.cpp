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

std::string file_stem_for(std::string_view name, std::string_view empty_name) {
  std::string s;
  for (const char c : name) {
    const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      c == '-' || c == '_' || c == '.';
    s.push_back(keep ? c : '_');
  }
  s.erase(0, s.find_first_not_of('.') == std::string::npos ? s.size() : s.find_first_not_of('.'));
  if (s.size() > 100) s.resize(100);
  while (!s.empty() && s.back() == '.') s.pop_back();
  return s.empty() ? std::string(empty_name) : s;
}

std::string UniqueNames::make(const std::string& base) {
  std::string out = base;
  if (used_.contains(key(out))) {
    int& n = next_.try_emplace(key(base), 2).first->second;
    do {
      out = base + "_" + std::to_string(n++);
    } while (used_.contains(key(out)));
  }
  used_.insert(key(out));
  return out;
}

std::string_view next_word(std::string_view& s) {
  s = trim(s, kWhiteSpace);
  const size_t n = std::min(s.find_first_of(kWhiteSpace), s.size());
  const std::string_view word = s.substr(0, n);
  s.remove_prefix(n);
  return word;
}

}  // namespace segmesh
