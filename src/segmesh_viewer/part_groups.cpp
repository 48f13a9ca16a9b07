#include "segmesh_viewer/part_groups.hpp"

#include <algorithm>
#include <cctype>

namespace segmesh::viewer {

namespace {

// "tibia_12" -> "tibia"; a name without a numeric suffix stays as it is.
std::string without_component_suffix(const std::string& name) {
  const size_t underscore = name.rfind('_');
  if (underscore == std::string::npos || underscore == 0 || underscore + 1 == name.size()) return name;
  const bool digits = std::all_of(name.begin() + underscore + 1, name.end(),
                                  [](unsigned char c) { return std::isdigit(c) != 0; });
  return digits ? name.substr(0, underscore) : name;
}

}  // namespace

std::vector<PartGroup> group_parts_by_label(const Scene& scene) {
  std::vector<PartGroup> groups;
  for (size_t i = 0; i < scene.parts.size(); ++i) {
    const Part& part = scene.parts[i];
    auto it = std::find_if(groups.begin(), groups.end(),
                           [&](const PartGroup& g) { return g.label == part.label; });
    if (it == groups.end()) {
      groups.push_back(PartGroup{part.label, without_component_suffix(part.name), part.role, {}});
      it = groups.end() - 1;
    }
    it->parts.push_back(i);
  }
  return groups;
}

bool group_all_visible(const Scene& scene, const PartGroup& group) {
  return std::all_of(group.parts.begin(), group.parts.end(),
                     [&](size_t i) { return scene.parts[i].visible; });
}

bool group_none_visible(const Scene& scene, const PartGroup& group) {
  return std::none_of(group.parts.begin(), group.parts.end(),
                      [&](size_t i) { return scene.parts[i].visible; });
}

}  // namespace segmesh::viewer
