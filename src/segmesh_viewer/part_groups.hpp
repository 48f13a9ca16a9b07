// The parts list grouped by label: one group per label value (parts of a label are its connected
// components), in the order of the labels' first parts, for a tree of checkboxes. A group's name
// is its first part's name without the "_<k>" component suffix the pipeline adds (part_name in
// pipeline.hpp), so "bone_1", "bone_2" give the group "bone"; parts read from a mesh file that
// carries no labels (label 0) form one group.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "segmesh/scene.hpp"

namespace segmesh::viewer {

struct PartGroup {
  int32_t label = 0;
  std::string name;
  Role role = Role::other;     // the first part's role
  std::vector<size_t> parts;   // indices into Scene::parts, in scene order
};

std::vector<PartGroup> group_parts_by_label(const Scene& scene);

// Whether every / no part of the group is visible (a group checkbox shows the mixed state).
bool group_all_visible(const Scene& scene, const PartGroup& group);
bool group_none_visible(const Scene& scene, const PartGroup& group);

}  // namespace segmesh::viewer
