// The field one part is extracted from: its component cut out of the volume on the component's
// bounding box, grown by a margin of background on every side.
//
// The margin is what closes every surface: cells at the volume border see background beyond it, as
// if the volume were padded, so a part touching the border still gets a closed mesh. Two voxels of
// margin keep the gradients (and so the normals) of the border voxels exact for both the central
// and the Sobel operator. The field's Grid is the volume's grid moved to the crop, so extraction
// yields world coordinates directly.
#pragma once

#include <array>

#include "segmesh/components.hpp"
#include "segmesh/volume.hpp"

namespace segmesh {

inline constexpr int kFieldMargin = 2;

// Voxels of margin along each axis.
using FieldMargin = std::array<int64_t, 3>;
inline constexpr FieldMargin kDefaultFieldMargin{kFieldMargin, kFieldMargin, kFieldMargin};

// The volume's grid moved to the component's bounding box grown by `margin`.
Grid component_grid(const Grid& grid, const Component& component,
                    FieldMargin margin = kDefaultFieldMargin);

// 1 inside the component, 0 elsewhere (other components and other labels included).
Volume<uint8_t> component_mask(const Grid& grid, const Components& components,
                               const Component& component,
                               FieldMargin margin = kDefaultFieldMargin);

// A grey-value volume's values around the component. Voxels at or above iso that belong to other
// components are lowered to just below iso (so they never join this part's surface), and the margin
// outside the volume holds `background` (< iso).
template <class T>
Volume<float> component_values(const Volume<T>& volume, const Components& components,
                               const Component& component, double iso, float background,
                               FieldMargin margin = kDefaultFieldMargin);

extern template Volume<float> component_values(const Volume<uint8_t>&, const Components&,
                                               const Component&, double, float, FieldMargin);
extern template Volume<float> component_values(const Volume<int16_t>&, const Components&,
                                               const Component&, double, float, FieldMargin);
extern template Volume<float> component_values(const Volume<uint16_t>&, const Components&,
                                               const Component&, double, float, FieldMargin);
extern template Volume<float> component_values(const Volume<int32_t>&, const Components&,
                                               const Component&, double, float, FieldMargin);
extern template Volume<float> component_values(const Volume<float>&, const Components&,
                                               const Component&, double, float, FieldMargin);

}  // namespace segmesh
