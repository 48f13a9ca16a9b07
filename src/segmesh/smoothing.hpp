// Mesh smoothing: moves vertices to take the voxel staircase out of extracted surfaces, keeping
// the connectivity. Four filters, all built on the umbrella operator
//   L(p)_i = avg_{j in N(i)} p_j - p_i     (N(i): the vertices sharing an edge with i)
// so every vertex is treated as interior (our meshes are closed; like 3D Slicer's setting with
// boundary and feature-edge smoothing off). The average runs over the triangles at i, each adding
// its other two corners, so on a closed edge-manifold mesh (every mesh segmesh extracts) every
// neighbour counts twice and the average is the plain one; elsewhere a neighbour weighs as many
// triangles as share its edge with i (one across a boundary edge, three at a fin of three
// triangles). Every sweep is a Jacobi step: all vertices read the previous positions and write a
// second buffer (the "simultaneous" version of the references).
//
// - laplacian: p' = p + lambda L(p), `iterations` times. lambda = 1 moves every vertex to the
//   average of its neighbours (eq. 31-32 of the reference thesis; Field 1988, "Laplacian smoothing
//   and Delaunay triangulations"). Shrinks: a convex surface moves towards its centre of curvature,
//   on a sphere of radius R by about lambda h^2 / (2 R) per step (h the edge length), so volume is
//   lost at every step and without bound (the mesh converges to a point).
// - hc: the HC algorithm of Vollmer, Mencl and Mueller ("Improved Laplacian smoothing of noisy
//   surface meshes", Eurographics 1999), simultaneous version. Per iteration, q = the previous
//   positions, o = the original ones:
//     p_i = avg_{j in N(i)} q_j
//     b_i = p_i - (alpha o_i + (1 - alpha) q_i)
//     p_i = p_i - (beta b_i + (1 - beta) / |N(i)| sum_{j in N(i)} b_j)
//   The thesis' Algorithm 1 sums b_i instead of b_j and drops the parentheses (slips listed in
//   ../shared/reference/README.md); this is the paper's form. The push-back by the differences
//   removes most of the Laplacian's shrinkage while keeping its smoothing of the staircase.
// - taubin: lambda|mu filtering (Taubin, "A signal processing approach to fair surface design",
//   SIGGRAPH 1995): a Laplacian step with taubin_lambda > 0 then one with taubin_mu < -lambda.
//   One iteration is one lambda step and one mu step (two sweeps), as the thesis' Algorithm 2 and
//   VCG (the library behind the thesis' numbers) count them. The transfer function per iteration
//   is f(k) = (1 - lambda k)(1 - mu k): 1 at k = 0 and at the pass-band frequency
//   k_pb = 1/lambda + 1/mu (0.1 for the defaults), so low frequencies (the shape) keep their size
//   and high ones (the staircase) are damped. Between 0 and k_pb the gain is slightly above 1, so
//   a smooth shape grows a little (+0.07 % volume for a 20 mm sphere after 20 iterations) instead
//   of shrinking; the staircase needs many iterations to go.
// - sinc: windowed sinc filtering (Taubin, Zhang and Golub, "Optimal surface smoothing as filter
//   design", ECCV 1996 / IBM research report RC-20404), as VTK's vtkWindowedSincPolyDataFilter
//   (Debian's VTK 9.1) with 3D Slicer's closed-surface settings up to Slicer 5.6: the filter
//   f(k) = sum_{n=0..N} c_n T_n(1 - k/2) (T_n the Chebyshev polynomials, N = iterations) is the
//   Chebyshev series of the ideal low pass with cut-off pass_band, weighted by a Hamming window
//   w_n = 0.54 + 0.46 cos(n pi / (N + 1)), its cut-off nudged by a Newton search until
//   f(pass_band) = 1 within 1e-3 (windowed_sinc_coefficients). It is applied by the three-term
//   Chebyshev recursion x_{n+1} = 2 (I - K/2) x_n - x_{n-1}, K = -L, one sweep per n, summing
//   c_n x_n. As VTK's NormalizeCoordinates (on in Slicer), the positions are first moved to the
//   centre of their bounding box and divided by its diagonal, and moved back afterwards. That
//   matters: the Hamming-windowed series has f(0) = sum c_n != 1 (1.0012 for Slicer's pass band
//   0.01 and 20 iterations, 0.9984 for 0.1 and 20, 1.0035 for 0.001 and 40), i.e. a uniform scaling
//   about the centre (later VTK versions offer other windows, Nuttall by default, to fix it).
//   Centring makes it a scaling about the mesh's own box centre, as in VTK and Slicer, instead of a
//   shift by 0.1 % of the distance to the world origin. On the same mesh the result matches
//   VTK 9.1's to float rounding (bench/compare_sphere_vtk.sh: 4e-5 mm). Shrinkage is small (f ~ 1
//   up to pass_band), but the f(0) scaling adds a size error of ~0.1 % of the distance from the box
//   centre.
//
// Volume, in short: Laplacian shrinks every time; HC, Taubin and windowed sinc change it much less
// (bench/smoothing_sphere.cpp measures all of them on a voxelised sphere of radius 20 mm: 2
// iterations of Laplacian -0.27 %, HC -0.001 %, Taubin (20) +0.07 %, sinc (Slicer's) +0.43 %).
//
// Guarantees: positions change, nothing else: vertex count, indices (so closedness and
// manifoldness of the connectivity) and colours stay. Vertices in no triangle with three distinct
// corners stay exactly where they are, and triangles with a repeated corner (no area) add nothing
// to the averages. Non-manifold meshes are fine. Afterwards the normals are recomputed (as
// compute_vertex_normals does). The filters run on the displacements from the original positions,
// in float (small quantities, kept to ~1e-7 of their size), and the result is added to the
// original positions in double (relative to the bounding box's centre where the sinc scales or
// the volume is restored), so meshes ~500 mm from the world origin lose no precision; it is
// rounded to float once at the end.
// Parallel (oneTBB) without an adjacency: each sweep is one pass over the triangles, each adding
// its terms to its three corners (triangle_scatter.hpp: chunks of triangles that touch disjoint
// vertex ids run side by side, each walked as four interleaved streams, in an order fixed by the
// mesh), then one pass over the vertices, so the output is identical for any thread count.
//
// Cost: O(iterations x triangles) time (HC: two sweeps per iteration, Taubin two, sinc one,
// Laplacian one) plus one read of the indices for the chunks; memory: 16 bytes per vertex per
// buffer, two buffers (three for the sinc), plus the normals the mesh gets (measured times per
// filter: docs/PERFORMANCE.md).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "segmesh/progress.hpp"
#include "segmesh/tri_mesh.hpp"

namespace segmesh {

enum class SmoothMethod { none, laplacian, hc, taubin, sinc };

// "none", "laplacian", "hc", "taubin", "sinc".
std::string_view smooth_method_name(SmoothMethod method);
std::optional<SmoothMethod> parse_smooth_method(std::string_view name);

// Windowed sinc's pass band unless told otherwise (see SmoothOptions::pass_band).
inline constexpr double kDefaultPassBand = 0.01;

struct SmoothOptions {
  SmoothMethod method = SmoothMethod::none;  // the pipeline picks its own default
  // 0: the method's own default (default_smooth_iterations): laplacian 2, hc 2, taubin 20 (= 40
  // sweeps), sinc 20. Taubin counts one lambda and one mu step as one iteration; sinc counts as
  // VTK's NumberOfIterations (N + 1 coefficients, N sweeps).
  int iterations = 0;
  double lambda = 1.0;  // Laplacian step; 1 moves each vertex to its neighbours' average
  // HC (Vollmer, Mencl and Mueller 1999): alpha weights the original positions against the
  // previous ones in b, beta the vertex's own difference against its neighbours'. Both in [0, 1].
  double alpha = 0.0, beta = 0.5;
  // Taubin's lambda and mu (the reference's values): pass band k_pb = 1/lambda + 1/mu ~ 0.1.
  double taubin_lambda = 0.5024, taubin_mu = -0.5289;
  // Windowed sinc pass band k_pb in (0, 2] (VTK's PassBand): 0.01 is 3D Slicer's default
  // (smoothing factor 0.5: 10^(-4 * 0.5)); smaller smooths more, 2 hardly at all.
  double pass_band = kDefaultPassBand;
  // Windowed sinc: divide the coefficients by their sum so that f(0) = 1 exactly. The Hamming-
  // windowed series scales the mesh by f(0) about its box centre (1.0012 at Slicer's settings:
  // 0.24 mm at the ends of a 400 mm bone); with unit gain a constant passes unchanged. false
  // reproduces VTK 9.1 and 3D Slicer up to 5.6 exactly.
  bool sinc_unit_gain = true;
  // Afterwards, give the mesh back its enclosed volume: all vertices move along their normals by
  // the one offset that restores it (small parts, a few voxels across, are where every smoothing
  // shrinks: a screw meshed at 0.2 x 0.2 x 2 mm loses 1-8 % without it). A part smoothing would
  // shrink below a quarter of its volume (a speck) keeps its unsmoothed positions. false gives the
  // plain filters, as the reference thesis and VTK run them.
  bool preserve_volume = true;
};

// The iteration count `iterations == 0` stands for.
int default_smooth_iterations(SmoothMethod method);

// The first field of `options` out of range, by its name in SmoothOptions ("alpha", "pass_band")
// with the rule it breaks and the value ("must be between 0 and 1 (got 2)"), or nullopt. The one
// list of the checks: smooth_mesh throws on it, resolve_meshing_options reports it by the
// command-line option's name.
struct OptionProblem {
  std::string_view option;
  std::string rule;
};
std::optional<OptionProblem> smooth_options_problem(const SmoothOptions& options);

// Smooths the positions of `mesh` in place (connectivity untouched) as described above, then
// recomputes its normals (compute_vertex_normals). SmoothMethod::none leaves the mesh untouched,
// normals included. Throws std::invalid_argument for options out of range (negative iterations,
// alpha or beta outside [0, 1], pass_band outside (0, 2], non-finite factors); Cancelled when
// progress is cancelled (checked once per iteration; update() reports the fraction of iterations
// done, the caller names the step). Precondition: every index is below the vertex count.
void smooth_mesh(TriMesh& mesh, const SmoothOptions& options, Progress& progress = null_progress());

// Sets mesh.normals to one unit normal per vertex: the sum of the cross products (b - a) x (c - a)
// of the triangles using it (each face normal weighted by twice its area; summed in float),
// normalised. A vertex with no triangle of non-zero area gets (0, 0, 1), so every normal is unit
// (glTF requires it). Outwards for a closed mesh wound counter-clockwise seen from outside.
// Parallel (triangle_scatter.hpp), identical for any thread count. Cost: O(triangles), 16 bytes
// per vertex of scratch.
void compute_vertex_normals(TriMesh& mesh);

// The Chebyshev coefficients c_0 .. c_N of the windowed sinc filter for N = iterations >= 1 and
// pass band k_pb in (0, 2], computed as VTK 9.1 does (Hamming window; cut-off offset found by up to
// 500 Newton steps until |f(k_pb) - 1| < 1e-3, none for N = 1). The filter's response at a
// frequency k in [0, 2] is sum_n c_n cos(n acos(1 - k/2)). Exposed for tests and reports.
// With unit_gain, the coefficients are then divided by their sum (f(0) = 1).
std::vector<double> windowed_sinc_coefficients(int iterations, double pass_band,
                                               bool unit_gain = false);

}  // namespace segmesh
