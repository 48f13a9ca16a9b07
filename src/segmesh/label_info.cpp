#include "segmesh/label_info.hpp"

#include <algorithm>
#include <cctype>

namespace segmesh {

std::string_view role_name(Role role) {
  switch (role) {
    case Role::bone: return "bone";
    case Role::implant: return "implant";
    case Role::other: return "other";
  }
  return "other";
}

std::optional<Role> parse_role(std::string_view text) {
  std::string lower(text);
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (lower == "bone") return Role::bone;
  if (lower == "implant") return Role::implant;
  if (lower == "other") return Role::other;
  return std::nullopt;
}

const LabelInfo* find_label_info(const std::vector<LabelInfo>& infos, int32_t label) {
  const auto it = std::find_if(infos.begin(), infos.end(),
                               [label](const LabelInfo& info) { return info.label == label; });
  return it == infos.end() ? nullptr : &*it;
}

}  // namespace segmesh
