#include "segmesh/extract_part.hpp"

#include <algorithm>
#include <variant>

#include "segmesh/component_field.hpp"
#include "segmesh/gaussian_filter.hpp"
#include "segmesh/marching_cubes.hpp"

namespace segmesh {

namespace {

// Smoothing recomputes the normals from the triangles: the gradient's would be thrown away.
bool vertex_normals(const MeshingOptions& o) {
  return o.smooth.method == SmoothMethod::none;
}

DcOptions dc_options(const MeshingOptions& o, double iso) {
  return {.iso = iso,
          .connectivity = o.connectivity,
          .normals = o.normals,
          .svd_eps = o.dc_svd_eps,
          .tolerance_mm = o.dc_tolerance_mm,
          .vertex_normals = vertex_normals(o)};
}

McOptions mc_options(const MeshingOptions& o, double iso) {
  return {.iso = iso,
          .connectivity = o.connectivity,
          .normals = o.normals,
          .vertex_normals = vertex_normals(o)};
}

// The method on a field.
template <class T>
TriMesh extract_field(const Volume<T>& field, const MeshingOptions& o, double iso,
                      Progress& progress) {
  if (o.method == Method::dual_contouring)
    return dual_contouring(field, dc_options(o, iso), progress);
  return marching_cubes(field, mc_options(o, iso), progress);
}

// The method on a label component's runs.
TriMesh extract_runs(const PartSource& s, const Component& c, const MeshingOptions& o,
                     Progress& progress, DcNeighbourhoods* solved) {
  const Grid& grid = s.image.grid();
  if (o.method == Method::dual_contouring) {
    return dual_contouring(grid, s.components, c, dc_options(o, 0.5), progress, solved);
  }
  return marching_cubes(grid, s.components, c, mc_options(o, 0.5), progress);
}

bool is_grey(const MeshingOptions& o) {
  return o.iso.has_value();
}

// Outside the volume a grey-value field continues with its lowest value (or just below iso).
float background(const PartSource& s, const MeshingOptions& o) {
  return is_grey(o) ? static_cast<float>(std::min(s.range.min, *o.iso - 1.0)) : 0.0f;
}

// Calls use(field) with the part's field cut out with `margin`: its 0/1 mask for a label, the
// values around it for a grey-value component.
template <class Use>
TriMesh with_field(const PartSource& s, const Component& c, const MeshingOptions& o,
                   FieldMargin margin, Use&& use) {
  if (!is_grey(o)) return use(component_mask(s.image.grid(), s.components, c, margin));
  return std::visit(
      [&](const auto& volume) {
        return use(component_values(volume, s.components, c, *o.iso, background(s, o), margin));
      },
      s.image.volume);
}

}  // namespace

PartMesh extract_part(const PartSource& s, const Component& c, const MeshingOptions& o,
                      Progress& progress, DcNeighbourhoods* solved) {
  const double iso = is_grey(o) ? *o.iso : 0.5;
  PartMesh out;
  if (o.volume_sigma_mm > 0) {
    const Grid& grid = s.image.grid();
    out.mesh =
        with_field(s, c, o, gaussian_margin(grid, o.volume_sigma_mm), [&](const auto& field) {
          SubProgress filtering(progress, 0, 0.5), extracting(progress, 0.5, 1);
          const auto smoothed =
              gaussian_filter(field, o.volume_sigma_mm, background(s, o), filtering);
          return extract_field(smoothed, o, iso, extracting);
        });
    if (!out.mesh.empty()) return out;
    out.unsmoothed_fallback = true;
  } else if (!is_grey(o)) {
    out.mesh = extract_runs(s, c, o, progress, solved);
    return out;
  }
  out.mesh = with_field(s, c, o, kDefaultFieldMargin,
                        [&](const auto& field) { return extract_field(field, o, iso, progress); });
  return out;
}

std::unique_ptr<DcNeighbourhoods> make_shared_neighbourhoods(const Grid& grid,
                                                             const MeshingOptions& o) {
  if (o.method != Method::dual_contouring || is_grey(o) || o.volume_sigma_mm > 0) return nullptr;
  return std::make_unique<DcNeighbourhoods>(grid, dc_options(o, 0.5));
}

}  // namespace segmesh
