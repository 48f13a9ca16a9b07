// What is known about a label value: its name, its role in surgery planning and its colour.
// Comes from a 3D Slicer .seg.nrrd header, from a --label-names TSV file, or from defaults.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace segmesh {

enum class Role { bone, implant, other };

std::string_view role_name(Role role);
// "bone", "implant" or "other" (case-insensitive); nullopt for anything else.
std::optional<Role> parse_role(std::string_view text);

struct Rgb {
  float r = 1, g = 1, b = 1;  // 0..1
};

struct LabelInfo {
  int32_t label = 0;
  std::string name;           // may be empty: unnamed
  std::optional<Role> role;   // unset: decided by defaults
  std::optional<Rgb> color;   // unset: decided by role
};

// The entry for `label` in `infos`, or nullptr.
const LabelInfo* find_label_info(const std::vector<LabelInfo>& infos, int32_t label);

}  // namespace segmesh
