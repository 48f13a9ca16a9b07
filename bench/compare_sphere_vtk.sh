#!/usr/bin/env bash
# segmesh's smoothing methods and 3D Slicer's default surface smoothing side by side on the same
# voxelised sphere: writes the sphere label map, meshes it with VTK as 3D Slicer does
# (vtkDiscreteFlyingEdges3D, then vtkWindowedSincPolyDataFilter with pass band 0.01 and 20
# iterations, Hamming window, coordinates normalised; ../shared/tools/peer_mesh.py), and scores
# the VTK meshes with the same program and definitions as segmesh's (bench/smoothing_sphere.cpp).
# It also runs segmesh's windowed sinc and Laplacian on VTK's unsmoothed meshes and compares them
# vertex by vertex with VTK's smoothed ones (vtkWindowedSincPolyDataFilter, vtkSmoothPolyDataFilter
# with relaxation 1 and 2 iterations, peer_mesh.py's vtk_laplacian_r1.0). The sinc filters
# agree to float rounding; the Laplacians differ by design (VTK's updates the points in place,
# one after the other; ours moves all of them at once, as the reference describes).
#
#   bench/compare_sphere_vtk.sh [BUILD_DIR] [OUT_DIR] [-- options for segmesh_smoothing_sphere]
#
# BUILD_DIR defaults to build/, OUT_DIR to a new temporary folder. Options after -- (e.g.
# --radius 20 --spacing 0.5,0.5,1.0, the defaults) choose the sphere. Needs Debian's
# python3-vtk9 python3-nibabel python3-numpy (python3-skimage, python3-scipy optional):
#   apt-get install -y python3-vtk9 python3-skimage python3-numpy python3-nibabel python3-scipy
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(dirname "$here")"
positional=()
while [[ $# -gt 0 && "$1" != "--" ]]; do positional+=("$1"); shift; done
[[ "${1:-}" == "--" ]] && shift
sphere_args=("$@")
build="${positional[0]:-$repo/build}"
out="${positional[1]:-$(mktemp -d /tmp/segmesh_sphere.XXXXXX)}"

program="$build/bench/segmesh_smoothing_sphere"
peer="$repo/../shared/tools/peer_mesh.py"
[[ -x "$program" ]] || { echo "missing $program: build the target segmesh_smoothing_sphere" >&2; exit 2; }
[[ -f "$peer" ]] || { echo "missing $peer" >&2; exit 2; }
/usr/bin/python3 -c 'import vtk, nibabel, numpy' 2>/dev/null || {
  echo "needs python3-vtk9 python3-nibabel python3-numpy (apt-get install -y ...)" >&2; exit 2; }

mkdir -p "$out"
labels="$out/sphere.nii.gz"
"$program" "${sphere_args[@]}" --write "$labels" > /dev/null

# --frame world: the STL files are in NIfTI world coordinates, RAS; --ras below turns them into
# our LPS frame (x and y negated), so both sets of meshes are scored against the same sphere.
/usr/bin/python3 "$peer" "$labels" \
  --methods vtk_discrete_flying_edges,vtk_discrete_flying_edges_sinc,vtk_discrete_marching_cubes,vtk_laplacian_r1.0 \
  --threads 1 --repeats 1 --frame world --out "$out/vtk" --json "$out/vtk.json"

stem="$out/vtk/sphere_label1"
"$program" "${sphere_args[@]}" --ras \
  --stl "VTK discrete flying edges=${stem}_vtk_discrete_flying_edges.stl" \
  --stl "VTK + windowed sinc (3D Slicer up to 5.6: pass band 0.01, 20 it)=${stem}_vtk_discrete_flying_edges_sinc.stl" \
  --stl "VTK discrete marching cubes=${stem}_vtk_discrete_marching_cubes.stl" \
  --stl "VTK + vtkSmoothPolyDataFilter (relaxation 1, 2 it)=${stem}_vtk_laplacian_r1.0.stl" \
  --check sinc "${stem}_vtk_discrete_flying_edges.stl" "${stem}_vtk_discrete_flying_edges_sinc.stl" \
  --check laplacian "${stem}_vtk_discrete_marching_cubes.stl" "${stem}_vtk_laplacian_r1.0.stl"
echo
echo "files in $out"
