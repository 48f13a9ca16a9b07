#include "segmesh/detail/dc_neighbourhood_cache.hpp"

#include "segmesh/detail/dc_neighbourhood_keys.hpp"

namespace segmesh {

DcNeighbourhoods::DcNeighbourhoods(const Grid& grid, const DcOptions& options)
    : tables(new Tables{grid.spacing,
                        grid.direction,
                        options.connectivity,
                        options.normals,
                        options.svd_eps,
                        options.vertex_normals,
                        {}}) {}

DcNeighbourhoods::~DcNeighbourhoods() = default;

}  // namespace segmesh

namespace segmesh::dc {

namespace {

// Sheet `piece` of a table entry from its index-space offset and normal sum (the normal only
// when vertex normals are asked for).
void store_sheet(const SheetSolve& s, SheetVertices& out, SheetNormals& normals, int piece,
                 Vec3d offset, Vec3d normal_sum) {
  const auto& sp = s.grid.spacing;
  const Vec3f o =
      to_float(s.grid.direction * Vec3d{offset.x * sp[0], offset.y * sp[1], offset.z * sp[2]});
  float* to = out.offset[piece];
  to[0] = o.x, to[1] = o.y, to[2] = o.z;
  if (!s.normals) return;
  const Vec3f n = world_normal(s.grid, normal_sum);
  float* tn = normals.normal[piece];
  tn[0] = n.x, tn[1] = n.y, tn[2] = n.z;
}

// The single sheet of the cell with neighbourhood `key`, solved in the frame of its mirror class
// and mirrored back into `out`; false (nothing written) when the class's cell does not hold
// exactly one sheet.
bool solve_mirrored(const SheetSolve& s, const std::array<uint64_t, 256>& relevant, uint64_t key,
                    SolvedNeighbourhoods& table, SheetVertices& out, SheetNormals& normals) {
  const CanonicalKey c = canonical_key(key & relevant[size_t(case_of_key(key))]);
  const int cs = case_of_key(c.key);
  if (s.pieces(cs) != 1) return false;
  const uint32_t class_entry = table.by_class.get(c.key, [&](CanonicalSheet& made) {
    const CellVertices v = solve_key(s, c.key, cs, nullptr);
    made = {{v.offset[0].x, v.offset[0].y, v.offset[0].z},
            {v.normal_sum[0].x, v.normal_sum[0].y, v.normal_sum[0].z}};
  });
  const CanonicalSheet& sheet = table.by_class[class_entry];
  double offset[3], normal_sum[3];
  for (int a = 0; a < 3; ++a) {
    const bool mirrored = (c.axes >> a & 1) != 0;
    offset[a] = mirrored ? 1 - sheet.offset[a] : sheet.offset[a];
    normal_sum[a] = mirrored ? -sheet.normal_sum[a] : sheet.normal_sum[a];
  }
  store_sheet(s, out, normals, 0, {offset[0], offset[1], offset[2]},
              {normal_sum[0], normal_sum[1], normal_sum[2]});
  return true;
}

}  // namespace

void solve_entry(const SheetSolve& s, const std::array<uint64_t, 256>& relevant,
                 SolvedNeighbourhoods& table, uint64_t key, int cs, int n, SheetVertices& out) {
  SheetNormals normals;
  if (n != 1 || !solve_mirrored(s, relevant, key, table, out, normals)) {
    const CellVertices full = solve_key(s, key, cs, nullptr);
    for (int p = 0; p < n; ++p) store_sheet(s, out, normals, p, full.offset[p], full.normal_sum[p]);
  }
  if (s.normals) table.normals.push_back(normals);
}

}  // namespace segmesh::dc
