// The built-in demo volume ("phantom"): a label map of a lower leg with a fractured tibia, an
// intact fibula and a fixation plate with six screws, so the demo, the benchmarks and the tests
// need no patient data.
//
// Why this anatomy: it is the kind of data of the reference thesis, whose CT6b data set is a
// 512 x 512 x 203 voxel CT at 0.197 x 0.197 x 2 mm of one fractured bone with implants. The default
// options reproduce that grid, so a run on the phantom costs what a run on such a CT costs: highly
// anisotropic voxels (2 mm slices, 10x the in-plane spacing), one large bone, thin separate metal
// parts, and bone-implant contact where the screws sit in the bone.
//
// Labels: 0 background, 1 bone, 2 implant.
//
// Frame. World millimetres, LPS axes (x towards the patient's left, y posterior, z superior),
// identity direction, origin chosen so the volume is centred on the world origin: voxel (i, j, k)
// is at ((i - (nx-1)/2) hx, (j - (ny-1)/2) hy, (k - (nz-1)/2) hz). It is a right leg seen in its
// own CT: the tibia medial (+x), the fibula lateral (-x) and posterior (+y), bone axes along z.
// The anatomy is defined in millimetres for the reference extent E = 100.864 x 100.864 x 406 mm
// (the default size times the default spacing) and scaled uniformly by
// s = min over the axes of (size * spacing / E), so it always fits and keeps its shape. At the
// default extent, and at any size/spacing with the same extent (for example 256 x 256 x 102 at
// 0.394 x 0.394 x 4 mm, where the z extent 408 mm is larger), s = 1 and the numbers below are
// exact millimetres; other sizes sample the same anatomy differently.
//
// Geometry at s = 1 (mm, relative to the volume centre):
// - Bone cross-sections: r(theta) = R(z) (1 + tri sin 3 theta + ell cos 2 theta) around the bone's
//   axis, theta measured from +x towards +y: a rounded triangle (corners at the anterior crest,
//   -90 deg, and at 30 and 150 deg, faces anteromedial, anterolateral, posterior), convex, solid.
//   Its area is pi R^2 (1 + (tri^2 + ell^2) / 2).
// - R(z) of a bone: rounded end cap of length c (R = R_end sqrt(1 - (d/c)^2), d the distance into
//   the cap from its inner end), then a flare from R_end to R_shaft over length L (smoothstep
//   3u^2 - 2u^3), the constant shaft, a flare to the other end's radius and another cap.
// - Tibia: axis at (x, y) = (12, -8), z from -191 to 191 (382 mm long). tri = 0.08, ell = -0.04.
//   Shaft R = 12 (24 mm medial-lateral, 25 mm anterior-posterior) from z = -115 to 95; distal flare
//   to R = 19 (38 x 40 mm) over 70 mm, cap 6 mm; proximal flare to R = 26 (the plateau,
//   51 x 54 mm) over 90 mm, cap 6 mm.
// - Fracture: an oblique plane through (12, -8, -50) with unit normal n = (0.433, 0.75, 0.5)
//   (60 deg from the bone axis, its in-plane part perpendicular to the screws), so the fracture
//   line rises about 40 mm across the shaft. Tibia voxels with |n . (p - F)| < 1.5 are removed:
//   a 3 mm gap at every point (6 mm along z, 3.5 mm in-plane). The fragments stay 26-separated
//   whenever hx|nx| + hy|ny| + hz|nz| < 3 mm (the farthest a 26-neighbour reaches across the gap):
//   1.24 mm at the default spacing, 2.47 mm at 0.394 x 0.394 x 4.
// - Fibula: axis at (-22, 18), 43 mm from the tibia's, z from -197 to 177 (374 mm), intact.
//   tri = 0.06, ell = 0. Shaft R = 6 (12 mm wide) from z = -142 to 127; distal flare (lateral
//   malleolus) to R = 8 over 50 mm, cap 5 mm; proximal flare (fibular head) to R = 10.5 over 45 mm,
//   cap 5 mm. At least 6 mm from the tibia everywhere.
// - Plate (label 2): on the tibia's anteromedial face, centred on the direction d = (cos -30 deg,
//   sin -30 deg) from the tibia's axis; tangent t = (0.5, 0.866). It is the set of points with
//   r_tibia(theta, z) < rho <= r_tibia(theta, z) + 4 (4 mm thick, lying on the bone surface and
//   curved with it), d-coordinate a > 0, and (tau, z) = (t . p, z) inside a stadium 13 mm wide
//   from z = -105 to 5 (110 mm long, rounded ends). Six plate holes are slots (stadia) 5.5 mm wide
//   (tau) and 11.2 mm long (z), centred on the screws: 1 mm clearance around the 3.5 mm shaft
//   in-plane, 3.85 mm along z, more than one slice, which is what keeps plate and screws apart
//   under 26-connectivity at 2 mm slices.
// - Screws (label 2): three per fragment at z = -94, -78, -62 (distal) and -38, -22, -6
//   (proximal), 12, 28 and 44 mm from the fracture centre, axes along d (perpendicular to the bone
//   axis) through the plate holes. Shaft diameter 3.5 mm, from 2 mm beyond the far cortex to the
//   head; head 6 mm diameter, 2.5 mm high, its underside 1 mm above the highest point of the plate
//   within 4 mm of the screw axis (33 mm long overall). Screws replace bone where they overlap it
//   (the shafts cross the whole tibia: bicortical). The screw axes lie at z = 2 mod 4 mm, so at
//   s = 1 a 4 mm slice grid centred like ours (102 slices) has a slice through every screw axis;
//   a 2 mm grid needs no such luck (the separations hold for any slice position).
//
// Component counts (26-connected), checked by the tests at 512 x 512 x 203 (0.197 x 0.197 x 2 mm)
// and 256 x 256 x 102 (0.394 x 0.394 x 4 mm): label 1 has 3 (proximal and distal tibia fragments,
// fibula), label 2 has 7 (plate, 6 screws). Nothing non-zero touches the volume border: the bones
// end inside the volume (at least 6 mm from the z faces) and keep 12.5 mm from the x and y faces.
// Part ends along z (bones, plate) avoid the slice positions of both grids, so no part is sampled
// exactly at a tip. The separations (fracture gap, hole clearance, head gap) hold at any sampling
// phase for in-plane spacing up to about 0.5 mm and slices up to 2 mm at s = 1 (also checked at
// 512 x 512 x 204, 511 x 511 x 203, 256 x 256 x 203 at 0.394 x 0.394 x 2 and at 1 mm slices). With
// 4 mm slices the counts hold only with the screw alignment above: 256 x 256 x 103 loses the
// shafts between slices (7 parts but screws without bone contact), 256 x 256 x 101 (s = 0.995)
// merges parts; coarser grids merge or lose parts too.
//
// Cost: each voxel is classified analytically (point-in-shape tests on the closed-form outlines,
// no allocation), only inside per-slice bounding boxes of the bones, in parallel over z-slices.
// The output depends only on the options, never on the thread count. Most of the time goes to
// allocating and zeroing the label array.
#pragma once

#include <array>
#include <cstdint>

#include "segmesh/volume.hpp"

namespace segmesh {

struct PhantomOptions {
  std::array<int64_t, 3> size{512, 512, 203};        // voxels, each 8..4096
  std::array<double, 3> spacing{0.197, 0.197, 2.0};  // mm, > 0: the reference thesis's CT
};

// The phantom label map (0 background, 1 bone, 2 implant) on the grid described by `options`.
// Throws segmesh::Error when a size is outside 8..4096 or a spacing is not positive and finite.
LabelVolume make_phantom(const PhantomOptions& options = {});

}  // namespace segmesh
