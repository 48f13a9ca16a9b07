#include "segmesh_viewer/meshing_settings.hpp"

#include <charconv>
#include <limits>

#include "segmesh/error.hpp"

namespace segmesh::viewer {

std::vector<int32_t> parse_label_list(const std::string& text) {
  std::vector<int32_t> labels;
  size_t i = 0;
  while (i < text.size()) {
    if (text[i] == ',' || text[i] == ' ' || text[i] == '\t') {
      ++i;
      continue;
    }
    size_t end = i;
    while (end < text.size() && text[end] != ',' && text[end] != ' ' && text[end] != '\t') ++end;
    const std::string token = text.substr(i, end - i);
    int64_t value = 0;
    const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc() || ptr != token.data() + token.size() ||
        value < std::numeric_limits<int32_t>::min() || value > std::numeric_limits<int32_t>::max()) {
      throw Error("labels: \"" + token + "\" is not a whole number (write labels like 1,2)");
    }
    labels.push_back(static_cast<int32_t>(value));
    i = end;
  }
  return labels;
}

MeshingOptions meshing_options(const MeshingSettings& settings) {
  MeshingOptions options;
  options.method = settings.method;
  options.normals = settings.normals;
  options.smooth.method = settings.smooth;
  options.smooth.iterations = settings.iterations;
  options.labels = parse_label_list(settings.labels);
  return resolve_meshing_options(options);
}

}  // namespace segmesh::viewer
