// The built-in phantom: its grid, determinism across thread counts, its labels, its connected
// components (counted by a breadth-first search written here), its bone volume against the closed
// form of the geometry documented in phantom.hpp, its distance from the border, and the
// bone-implant contact later tests rely on.
#include "segmesh/phantom.hpp"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "segmesh/error.hpp"

namespace segmesh {
namespace {

constexpr double kPi = 3.14159265358979323846;

const LabelVolume& default_phantom() {
  static const LabelVolume v = make_phantom();
  return v;
}

const LabelVolume& half_resolution_phantom() {
  static const LabelVolume v =
      make_phantom({.size = {256, 256, 102}, .spacing = {0.394, 0.394, 4.0}});
  return v;
}

struct PhantomComponent {
  int64_t voxels = 0;
  bool touches_bone = false;  // some voxel is 6-adjacent to a label-1 voxel
};

// The 26-connected components of `label`, by a plain breadth-first search.
std::vector<PhantomComponent> components_of(const LabelVolume& v, int32_t label) {
  const auto [nx, ny, nz] = v.grid.dims;
  std::vector<uint8_t> seen(v.voxels.size(), 0);
  std::vector<int64_t> queue;
  std::vector<PhantomComponent> result;
  for (int64_t start = 0; start < int64_t(v.voxels.size()); ++start) {
    if (v.voxels[size_t(start)] != label || seen[size_t(start)]) continue;
    PhantomComponent c;
    queue.assign(1, start);
    seen[size_t(start)] = 1;
    for (size_t head = 0; head < queue.size(); ++head) {
      const int64_t at = queue[head];
      const int64_t i = at % nx, j = (at / nx) % ny, k = at / (nx * ny);
      ++c.voxels;
      for (int dk = -1; dk <= 1; ++dk) {
        for (int dj = -1; dj <= 1; ++dj) {
          for (int di = -1; di <= 1; ++di) {
            const int64_t a = i + di, b = j + dj, e = k + dk;
            if (a < 0 || b < 0 || e < 0 || a >= nx || b >= ny || e >= nz) continue;
            const int64_t n = (e * ny + b) * nx + a;
            const int32_t value = v.voxels[size_t(n)];
            if (std::abs(di) + std::abs(dj) + std::abs(dk) == 1 && value == 1)
              c.touches_bone = true;
            if (value == label && !seen[size_t(n)]) {
              seen[size_t(n)] = 1;
              queue.push_back(n);
            }
          }
        }
      }
    }
    result.push_back(c);
  }
  std::sort(result.begin(), result.end(),
            [](const auto& a, const auto& b) { return a.voxels > b.voxels; });
  return result;
}

int64_t count_label(const LabelVolume& v, int32_t label) {
  return std::count(v.voxels.begin(), v.voxels.end(), label);
}

// Components: 3 of bone (two tibia fragments and the fibula, each large), 7 of implant (the plate,
// the largest, and six screws of about equal size), each implant part touching bone.
void expect_phantom_components(const LabelVolume& v) {
  const auto bone = components_of(v, 1);
  ASSERT_EQ(bone.size(), 3u);
  // The smallest bone part (the fibula or the distal tibia fragment) is well over 10% of the bone.
  EXPECT_GT(bone[2].voxels * 10, count_label(v, 1));

  const auto implant = components_of(v, 2);
  ASSERT_EQ(implant.size(), 7u);
  EXPECT_GT(implant[0].voxels, 3 * implant[1].voxels);  // the plate
  EXPECT_LT(implant[1].voxels, implant[6].voxels * 13 / 10) << "screws differ in size";
  for (size_t c = 0; c < implant.size(); ++c) {
    EXPECT_TRUE(implant[c].touches_bone) << "implant component " << c << " has no bone contact";
  }
}

// The volume of a long bone of phantom.hpp: caps (half ellipsoids), smoothstep flares and the
// shaft, times the cross-section's area factor 1 + (tri^2 + ell^2) / 2.
double long_bone_volume(double cap, double r_lo, double flare_lo, double r_shaft, double shaft,
                        double r_hi, double flare_hi, double tri, double ell) {
  // Integral over u in [0, 1] of (r + (R - r) s(u))^2, s the smoothstep: int s = 1/2,
  // int s^2 = 13/35.
  const auto flare = [r_shaft](double r, double length) {
    const double d = r_shaft - r;
    return length * (r * r + r * d + d * d * 13.0 / 35.0);
  };
  const double caps = 2.0 / 3.0 * cap * (r_lo * r_lo + r_hi * r_hi);
  return kPi * (1 + (tri * tri + ell * ell) / 2) *
         (caps + flare(r_lo, flare_lo) + r_shaft * r_shaft * shaft + flare(r_hi, flare_hi));
}

// The bone volume (mm3) the geometry of phantom.hpp encloses at scale 1.
double analytic_bone_volume() {
  const double tri = 0.08, ell = -0.04;
  const double tibia = long_bone_volume(6, 19, 70, 12, 210, 26, 90, tri, ell);
  const double fibula = long_bone_volume(5, 8, 50, 6, 269, 10.5, 45, 0.06, 0);
  // The fracture gap: a 3 mm slab at 60 deg through the shaft removes 3 / cos 60 mm of shaft.
  const double gap = 3.0 / 0.5 * kPi * (1 + (tri * tri + ell * ell) / 2) * 12 * 12;
  // Six screw tunnels through the shaft along -30 deg: from r(-30 deg) to r(150 deg).
  const double chord = 12 * ((1 - tri + ell / 2) + (1 + tri + ell / 2));
  const double screws = 6 * kPi * 1.75 * 1.75 * chord;
  return tibia + fibula - gap - screws;
}

TEST(Phantom, DefaultGridIsTheReferenceCt) {
  const LabelVolume& v = default_phantom();
  EXPECT_EQ(v.grid.dims, (std::array<int64_t, 3>{512, 512, 203}));
  EXPECT_EQ(v.grid.spacing, (std::array<double, 3>{0.197, 0.197, 2.0}));
  EXPECT_EQ(v.grid.direction, identity3());
  // Centred on the world origin: voxel (0, 0, 0) and the last voxel are mirror images.
  EXPECT_NEAR(v.grid.origin[0], -255.5 * 0.197, 1e-9);
  EXPECT_NEAR(v.grid.origin[1], -255.5 * 0.197, 1e-9);
  EXPECT_NEAR(v.grid.origin[2], -202.0, 1e-9);
  const Vec3d last = v.grid.to_world({511, 511, 202});
  EXPECT_NEAR(last.x, -v.grid.origin[0], 1e-9);
  EXPECT_NEAR(last.z, -v.grid.origin[2], 1e-9);
  EXPECT_EQ(v.voxels.size(), v.grid.voxel_count());
}

TEST(Phantom, SameBytesEveryCallAndAnyThreadCount) {
  const LabelVolume& first = default_phantom();
  EXPECT_TRUE(make_phantom().voxels == first.voxels);
  LabelVolume serial;
  tbb::task_arena(1).execute([&] { serial = make_phantom(); });
  EXPECT_TRUE(serial.voxels == first.voxels);
}

TEST(Phantom, HasOnlyBackgroundBoneAndImplant) {
  const LabelVolume& v = default_phantom();
  std::array<int64_t, 3> counts{};
  for (int32_t x : v.voxels) {
    ASSERT_TRUE(x >= 0 && x <= 2) << "label " << x;
    ++counts[size_t(x)];
  }
  EXPECT_GT(counts[1], 0);
  EXPECT_GT(counts[2], 0);
  EXPECT_GT(counts[0], counts[1] + counts[2]);  // mostly background, as in a CT of a leg
}

TEST(Phantom, ThreeBonePartsAndSevenImplantPartsAtDefaultSize) {
  expect_phantom_components(default_phantom());
}

TEST(Phantom, ThreeBonePartsAndSevenImplantPartsAtHalfResolution) {
  expect_phantom_components(half_resolution_phantom());
}

TEST(Phantom, BoneVolumeMatchesTheGeometry) {
  const double expected = analytic_bone_volume();
  for (const LabelVolume* v : {&default_phantom(), &half_resolution_phantom()}) {
    const double volume = double(count_label(*v, 1)) * v->grid.voxel_volume();
    EXPECT_NEAR(volume / expected, 1.0, 0.02) << volume << " mm3 vs " << expected << " mm3";
  }
  // One mid-shaft slice (z = 40 mm, away from fracture, plate and flares): the two shaft sections.
  const LabelVolume& v = default_phantom();
  const int64_t k = 101 + 20;
  ASSERT_NEAR(v.grid.to_world({0, 0, double(k)}).z, 40.0, 1e-9);
  int64_t in_slice = 0;
  for (int64_t j = 0; j < 512; ++j)
    for (int64_t i = 0; i < 512; ++i) in_slice += v.at(i, j, k) == 1;
  const double area = double(in_slice) * 0.197 * 0.197;
  const double tibia = kPi * 12 * 12 * (1 + (0.08 * 0.08 + 0.04 * 0.04) / 2);
  const double fibula = kPi * 6 * 6 * (1 + 0.06 * 0.06 / 2);
  EXPECT_NEAR(area / (tibia + fibula), 1.0, 0.01) << area << " mm2";
}

TEST(Phantom, NothingTouchesTheBorder) {
  for (const LabelVolume* v : {&default_phantom(), &half_resolution_phantom()}) {
    const auto [nx, ny, nz] = v->grid.dims;
    int64_t on_border = 0;
    for (int64_t k = 0; k < nz; ++k)
      for (int64_t j = 0; j < ny; ++j)
        for (int64_t i = 0; i < nx; ++i) {
          const bool border =
              i == 0 || j == 0 || k == 0 || i == nx - 1 || j == ny - 1 || k == nz - 1;
          if (border && v->at(i, j, k) != 0) ++on_border;
        }
    EXPECT_EQ(on_border, 0);
  }
}

TEST(Phantom, ScrewsSitInTheBone) {
  // Runs of implant voxels along x with bone at both ends: shafts crossing the tibia. Each of the
  // six screws adds such runs in its own slices. (Every implant part touching bone is checked in
  // expect_phantom_components.)
  for (const LabelVolume* v : {&default_phantom(), &half_resolution_phantom()}) {
    const auto [nx, ny, nz] = v->grid.dims;
    int slices_with_embedded_screws = 0;
    for (int64_t k = 0; k < nz; ++k) {
      int64_t embedded = 0;
      for (int64_t j = 0; j < ny; ++j)
        for (int64_t i = 1; i + 1 < nx; ++i) {
          if (v->at(i, j, k) != 2 || v->at(i - 1, j, k) != 1) continue;
          int64_t end = i;
          while (end + 1 < nx && v->at(end, j, k) == 2) ++end;
          if (v->at(end, j, k) == 1) embedded += end - i;
        }
      slices_with_embedded_screws += embedded > 0;
    }
    EXPECT_GE(slices_with_embedded_screws, 6);
  }
}

TEST(Phantom, AnySizeGivesTheSameAnatomyScaledToFit) {
  // 1 mm isotropic voxels in a 96 x 96 x 192 mm box: the anatomy shrinks uniformly to fit the
  // z extent (s = 192 / 406) and keeps its bone volume, s^3 times the design's.
  const LabelVolume v = make_phantom({.size = {96, 96, 192}, .spacing = {1, 1, 1}});
  const double scale = std::min(96 / (512 * 0.197), 192 / 406.0);
  const double volume = double(count_label(v, 1)) * v.grid.voxel_volume();
  EXPECT_NEAR(volume / (analytic_bone_volume() * scale * scale * scale), 1.0, 0.03);
  EXPECT_GT(count_label(v, 2), 0);
  const auto [nx, ny, nz] = v.grid.dims;
  for (int64_t j = 0; j < ny; ++j)
    for (int64_t i = 0; i < nx; ++i) {
      ASSERT_EQ(v.at(i, j, 0), 0);
      ASSERT_EQ(v.at(i, j, nz - 1), 0);
    }
}

TEST(Phantom, RejectsInvalidOptions) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW(make_phantom({.size = {7, 512, 203}}), Error);
  EXPECT_THROW(make_phantom({.size = {512, 4097, 203}}), Error);
  EXPECT_THROW(make_phantom({.size = {512, 512, -1}}), Error);
  for (double bad : {0.0, -0.197, nan, inf}) {
    EXPECT_THROW(make_phantom({.size = {8, 8, 8}, .spacing = {0.197, 0.197, bad}}), Error) << bad;
    EXPECT_THROW(make_phantom({.size = {8, 8, 8}, .spacing = {bad, 1, 1}}), Error) << bad;
  }
  EXPECT_NO_THROW(make_phantom({.size = {8, 8, 8}, .spacing = {1, 1, 1}}));
  try {
    make_phantom({.size = {512, 512, 4}});
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("512x512x4"), std::string::npos) << e.what();
  }
  try {
    make_phantom({.spacing = {0.197, 0.197, 0}});
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("0.197x0.197x0)"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace segmesh
