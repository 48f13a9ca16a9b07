#include "segmesh_io/label_names.hpp"

#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <string_view>

#include "segmesh/error.hpp"
#include "segmesh_io/detail/text.hpp"

namespace segmesh {

namespace fs = std::filesystem;

namespace {

std::vector<std::string_view> split_tabs(std::string_view line) {
  std::vector<std::string_view> fields;
  size_t start = 0;
  for (size_t tab; (tab = line.find('\t', start)) != std::string_view::npos; start = tab + 1) {
    fields.push_back(trim(line.substr(start, tab - start)));
  }
  fields.push_back(trim(line.substr(start)));
  return fields;
}

}  // namespace

std::vector<LabelInfo> read_label_names(const fs::path& tsv) {
  std::error_code ec;
  if (!fs::exists(tsv, ec)) throw Error(tsv.string() + ": no such file");
  std::ifstream file(tsv);
  if (!file) throw Error(tsv.string() + ": cannot open the file (" + std::strerror(errno) + ")");

  std::vector<LabelInfo> labels;
  std::map<int32_t, int> line_of_label;
  bool first_entry = true;
  int line_number = 0;
  for (std::string line; std::getline(file, line);) {
    ++line_number;
    const std::string_view text = trim(line);
    if (text.empty() || text.front() == '#') continue;
    auto fail = [&](const std::string& what) {
      return Error(tsv.string() + ":" + std::to_string(line_number) + ": " + what);
    };
    const std::vector<std::string_view> fields = split_tabs(line);

    LabelInfo info;
    const std::string_view label = fields[0];
    const auto [end, parse_error] =
        std::from_chars(label.data(), label.data() + label.size(), info.label);
    const bool is_number = parse_error == std::errc() && end == label.data() + label.size();
    const bool starts_with_number = parse_error == std::errc();
    if (!starts_with_number && first_entry) {  // a header line such as "label<TAB>name<TAB>role"
      first_entry = false;
      continue;
    }
    first_entry = false;
    if (starts_with_number && label.find_first_of(" ,;") != std::string_view::npos) {
      throw fail("fields must be separated by tabs; expected label<TAB>name[<TAB>role]");
    }
    if (!is_number) {
      throw fail("\"" + std::string(label) +
                 "\" is not an integer label; expected "
                 "label<TAB>name[<TAB>role]");
    }
    if (fields.size() < 2 || fields[1].empty()) {
      throw fail("label " + std::to_string(info.label) +
                 " has no name; expected "
                 "label<TAB>name[<TAB>role] separated by tabs");
    }
    if (fields.size() > 3) {
      throw fail("too many fields (" + std::to_string(fields.size()) +
                 "); expected label<TAB>name[<TAB>role]");
    }
    info.name = std::string(fields[1]);
    if (fields.size() == 3 && !fields[2].empty()) {
      info.role = parse_role(fields[2]);
      if (!info.role) {
        throw fail("unknown role \"" + std::string(fields[2]) +
                   "\"; expected bone, implant or other");
      }
    }
    if (const auto [it, inserted] = line_of_label.emplace(info.label, line_number); !inserted) {
      throw fail("label " + std::to_string(info.label) + " is already named on line " +
                 std::to_string(it->second));
    }
    labels.push_back(std::move(info));
  }
  if (file.bad()) throw Error(tsv.string() + ": reading failed");
  if (labels.empty())
    throw Error(tsv.string() +
                ": no label names found; expected lines of label<TAB>name[<TAB>role]");
  return labels;
}

}  // namespace segmesh
