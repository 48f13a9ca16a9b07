#include "segmesh/phantom.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "segmesh/error.hpp"

namespace segmesh {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The extent (mm) the anatomy is designed for: the default size times the default spacing.
constexpr std::array<double, 3> kReferenceExtent{512 * 0.197, 512 * 0.197, 203 * 2.0};

double smoothstep(double u) {
  return u * u * (3 - 2 * u);
}

// Outline factor of a cross-section in the direction (c, s) = (cos theta, sin theta):
// 1 + tri sin 3 theta + ell cos 2 theta, written without trigonometric calls.
double section_factor(double c, double s, double tri, double ell) {
  return 1 + tri * s * (3 - 4 * s * s) + ell * (c * c - s * s);
}

// A long bone along z: a cross-section of fixed shape whose scale R(z) follows a cap, a flare, the
// shaft, a flare and a cap.
struct LongBone {
  double cx = 0, cy = 0;      // axis position, mm
  double z_lo = 0, z_hi = 0;  // ends
  double cap = 0;             // length of each rounded end cap
  double r_lo = 0, flare_lo = 0;
  double r_shaft = 0;
  double r_hi = 0, flare_hi = 0;
  double tri = 0, ell = 0;

  // R(z); 0 outside the bone's z-range.
  double radius(double z) const {
    if (z < z_lo || z > z_hi) return 0;
    const double d_lo = z - z_lo, d_hi = z_hi - z;
    if (d_lo < cap) {
      const double u = (cap - d_lo) / cap;
      return r_lo * std::sqrt(1 - u * u);
    }
    if (d_hi < cap) {
      const double u = (cap - d_hi) / cap;
      return r_hi * std::sqrt(1 - u * u);
    }
    if (d_lo < cap + flare_lo) return r_lo + (r_shaft - r_lo) * smoothstep((d_lo - cap) / flare_lo);
    if (d_hi < cap + flare_hi) return r_hi + (r_shaft - r_hi) * smoothstep((d_hi - cap) / flare_hi);
    return r_shaft;
  }
  double max_factor() const { return 1 + std::abs(tri) + std::abs(ell); }
};

struct Screw {
  double zc = 0;      // axis height
  double a_tip = 0;   // shaft from a_tip to a_head along the plate direction d
  double a_head = 0;  // head from a_head to a_head + head height
};

// Every dimension in millimetres at scale 1; see the header for the anatomy.
struct Geometry {
  // clang-format off
  LongBone tibia{.cx = 12, .cy = -8, .z_lo = -191, .z_hi = 191, .cap = 6,
                 .r_lo = 19, .flare_lo = 70, .r_shaft = 12, .r_hi = 26, .flare_hi = 90,
                 .tri = 0.08, .ell = -0.04};
  LongBone fibula{.cx = -22, .cy = 18, .z_lo = -197, .z_hi = 177, .cap = 5,
                  .r_lo = 8, .flare_lo = 50, .r_shaft = 6, .r_hi = 10.5, .flare_hi = 45,
                  .tri = 0.06, .ell = 0};
  // clang-format on

  // Plate and screw direction d (from the tibia's axis, anteromedial) and tangent t.
  double dx = std::cos(-kPi / 6), dy = std::sin(-kPi / 6);
  double tx = -dy, ty = dx;

  // Fracture plane through (tibia axis, fracture_z), normal 60 deg from z, its horizontal part
  // along t.
  double fracture_z = -50;
  double nx = std::sin(kPi / 3) * tx, ny = std::sin(kPi / 3) * ty, nz = std::cos(kPi / 3);
  double fracture_half_gap = 1.5;

  double plate_z_lo = -105, plate_z_hi = 5, plate_half_width = 6.5, plate_thickness = 4;
  // Slots rather than round holes: along z the shaft needs more than one slice of clearance (2 mm
  // at the default spacing, 4 mm at half resolution with the screws on slices) to be a separate
  // 26-connected part; across (tau), 1 mm clears a 0.2-0.4 mm pixel's neighbours easily.
  double slot_half_width = 2.75, slot_half_length = 5.6;

  double shaft_radius = 1.75, head_radius = 3, head_height = 2.5, head_gap = 1;
  double tip_protrusion = 2;
  std::array<Screw, 6> screws{};

  double implant_reach = 0;  // an upper bound of rho over the plate and the screws

  Geometry() {
    const std::array<double, 6> offsets{-44, -28, -12, 12, 28, 44};
    for (size_t n = 0; n < screws.size(); ++n) {
      Screw& s = screws[n];
      s.zc = fracture_z + offsets[n];
      // The largest tibia scale near the screw bounds the plate's outer surface there.
      double r = 0;
      for (double dz = -8; dz <= 8; dz += 0.5) r = std::max(r, tibia.radius(s.zc + dz));
      // Highest point (along d) of the plate's outer surface within head_radius + head_gap of
      // the axis, so the head's underside clears the plate by at least head_gap everywhere.
      const double reach = head_radius + head_gap;
      double top = 0;
      for (int q = -4000; q <= 4000; ++q) {
        const double phi = q * (kPi / 2) / 4000;  // angle from d
        const double theta = -kPi / 6 + phi;
        const double rho =
            r * section_factor(std::cos(theta), std::sin(theta), tibia.tri, tibia.ell) +
            plate_thickness;
        if (std::abs(rho * std::sin(phi)) <= reach) top = std::max(top, rho * std::cos(phi));
      }
      s.a_head = top + head_gap;
      // Far cortex: the opposite direction, theta = 150 deg.
      const double far =
          tibia.radius(s.zc) *
          section_factor(std::cos(5 * kPi / 6), std::sin(5 * kPi / 6), tibia.tri, tibia.ell);
      s.a_tip = -(far + tip_protrusion);
      implant_reach = std::max({implant_reach, std::hypot(s.a_head + head_height, head_radius),
                                std::hypot(s.a_tip, shaft_radius)});
    }
    double r_plate = 0;
    for (double z = plate_z_lo; z <= plate_z_hi; z += 0.5)
      r_plate = std::max(r_plate, tibia.radius(z));
    implant_reach = std::max(implant_reach, r_plate * tibia.max_factor() + plate_thickness);
  }
};

// Is (u, v) inside the stadium of half-width w around the segment u = 0, |v| <= half_length - w?
bool in_stadium(double u, double v, double w, double half_length) {
  const double excess = std::max(0.0, std::abs(v) - (half_length - w));
  return u * u + excess * excess <= w * w;
}

// Index range [first, last] of the voxels whose world coordinate lies in [lo, hi]; empty when
// first > last.
std::array<int64_t, 2> index_range(double lo, double hi, double origin, double spacing, int64_t n) {
  const double first = std::ceil((lo - origin) / spacing);
  const double last = std::floor((hi - origin) / spacing);
  return {static_cast<int64_t>(std::clamp(first, 0.0, double(n))),
          static_cast<int64_t>(std::clamp(last, -1.0, double(n - 1)))};
}

template <class T>
std::string by(const std::array<T, 3>& v) {
  std::ostringstream text;
  text << v[0] << "x" << v[1] << "x" << v[2];
  return text.str();
}

void validate(const PhantomOptions& options) {
  for (int64_t n : options.size) {
    if (n < 8 || n > 4096)
      throw Error("phantom: size must be 8..4096 voxels per axis (got " + by(options.size) + ")");
  }
  for (double h : options.spacing) {
    if (!std::isfinite(h) || h <= 0) {
      throw Error("phantom: spacing must be positive and finite, in mm (got " +
                  by(options.spacing) + ")");
    }
  }
}

}  // namespace

LabelVolume make_phantom(const PhantomOptions& options) {
  validate(options);
  static const Geometry g;

  LabelVolume volume;
  Grid& grid = volume.grid;
  grid.dims = options.size;
  grid.spacing = options.spacing;
  double scale = 1e300;
  for (int a = 0; a < 3; ++a) {
    grid.origin[a] = -0.5 * double(grid.dims[a] - 1) * grid.spacing[a];
    scale = std::min(scale, double(grid.dims[a]) * grid.spacing[a] / kReferenceExtent[a]);
  }
  volume.voxels.assign(grid.voxel_count(), 0);

  // Voxel coordinates in the design frame (mm at scale 1).
  const auto design_coordinates = [&](int a) {
    std::vector<double> c(size_t(grid.dims[a]));
    for (int64_t i = 0; i < grid.dims[a]; ++i)
      c[size_t(i)] = (grid.origin[a] + double(i) * grid.spacing[a]) / scale;
    return c;
  };
  const std::vector<double> xs = design_coordinates(0), ys = design_coordinates(1);
  const std::vector<double> zs = design_coordinates(2);

  const int64_t nx = grid.dims[0], ny = grid.dims[1];
  // The voxel box (in this slice) of the disc of radius r (design mm) around (cx, cy).
  const auto box = [&](double cx, double cy, double r) {
    const auto [i0, i1] =
        index_range((cx - r) * scale, (cx + r) * scale, grid.origin[0], grid.spacing[0], nx);
    const auto [j0, j1] =
        index_range((cy - r) * scale, (cy + r) * scale, grid.origin[1], grid.spacing[1], ny);
    return std::array<int64_t, 4>{i0, i1, j0, j1};
  };

  tbb::parallel_for(tbb::blocked_range<int64_t>(0, grid.dims[2]), [&](const auto& range) {
    for (int64_t k = range.begin(); k != range.end(); ++k) {
      const double z = zs[size_t(k)];
      int32_t* slice = volume.voxels.data() + grid.index(0, 0, k);

      // Tibia with the plate and the screws.
      const LongBone& tb = g.tibia;
      const double rt = tb.radius(z);
      const bool plate_here = z >= g.plate_z_lo && z <= g.plate_z_hi;
      std::array<const Screw*, 6> screws{};  // screws whose head reaches this slice
      std::array<const Screw*, 6> slots{};   // plate holes that reach this slice
      int screw_count = 0, slot_count = 0;
      for (const Screw& s : g.screws) {
        if (std::abs(z - s.zc) <= g.head_radius) screws[size_t(screw_count++)] = &s;
        if (std::abs(z - s.zc) <= g.slot_half_length) slots[size_t(slot_count++)] = &s;
      }
      const bool implant_here = plate_here || screw_count > 0;
      const double plate_v = z - 0.5 * (g.plate_z_lo + g.plate_z_hi);
      const double plate_half_length = 0.5 * (g.plate_z_hi - g.plate_z_lo);
      const double fracture_dz = g.nz * (z - g.fracture_z);
      const double tibia_reach = std::max(rt * tb.max_factor(), implant_here ? g.implant_reach : 0);
      if (tibia_reach > 0) {
        const auto [i0, i1, j0, j1] = box(tb.cx, tb.cy, tibia_reach);
        for (int64_t j = j0; j <= j1; ++j) {
          const double py = ys[size_t(j)] - tb.cy;
          int32_t* row = slice + j * nx;
          for (int64_t i = i0; i <= i1; ++i) {
            const double px = xs[size_t(i)] - tb.cx;
            const double rho2 = px * px + py * py;
            const double rho = std::sqrt(rho2);
            const double f = rho > 0 ? section_factor(px / rho, py / rho, tb.tri, tb.ell) : 1.0;
            const double surface = rt * f;  // the tibia's outline in this direction
            int32_t label = 0;
            if (rho <= surface &&
                std::abs(g.nx * px + g.ny * py + fracture_dz) >= g.fracture_half_gap) {
              label = 1;
            }
            if (implant_here) {
              const double a = g.dx * px + g.dy * py;
              const double tau = g.tx * px + g.ty * py;
              if (plate_here && a > 0 && rho > surface && rho <= surface + g.plate_thickness &&
                  in_stadium(tau, plate_v, g.plate_half_width, plate_half_length)) {
                bool in_hole = false;
                for (int s = 0; s < slot_count; ++s) {
                  in_hole = in_hole || in_stadium(tau, z - slots[size_t(s)]->zc, g.slot_half_width,
                                                  g.slot_half_length);
                }
                if (!in_hole) label = 2;
              }
              for (int s = 0; s < screw_count; ++s) {
                const Screw& sc = *screws[size_t(s)];
                const double dz = z - sc.zc;
                const double q = tau * tau + dz * dz;
                const bool shaft =
                    q <= g.shaft_radius * g.shaft_radius && a >= sc.a_tip && a <= sc.a_head;
                const bool head = q <= g.head_radius * g.head_radius && a >= sc.a_head &&
                                  a <= sc.a_head + g.head_height;
                if (shaft || head) label = 2;
              }
            }
            if (label > row[i]) row[i] = label;
          }
        }
      }

      // Fibula.
      const LongBone& fb = g.fibula;
      const double rf = fb.radius(z);
      if (rf > 0) {
        const auto [i0, i1, j0, j1] = box(fb.cx, fb.cy, rf * fb.max_factor());
        for (int64_t j = j0; j <= j1; ++j) {
          const double py = ys[size_t(j)] - fb.cy;
          int32_t* row = slice + j * nx;
          for (int64_t i = i0; i <= i1; ++i) {
            const double px = xs[size_t(i)] - fb.cx;
            const double rho = std::sqrt(px * px + py * py);
            const double f = rho > 0 ? section_factor(px / rho, py / rho, fb.tri, fb.ell) : 1.0;
            if (rho <= rf * f && row[i] < 1) row[i] = 1;
          }
        }
      }
    }
  });
  return volume;
}

}  // namespace segmesh
