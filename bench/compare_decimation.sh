#!/usr/bin/env bash
# segmesh's decimation against meshoptimizer and VTK's vtkQuadricDecimation at equal triangle
# counts on the built-in phantom (512 x 512 x 203), one Markdown table (docs/DECIMATION.md,
# "Against meshoptimizer and VTK"):
#   1. `segmesh phantom`, then `segmesh mesh` to a PLY per part, undecimated and with
#      `--decimate-error 0.2` (default options otherwise: conforming surfaces);
#   2. bench/vtk_decimate.py: vtkQuadricDecimation per part to the triangles segmesh left it
#      (VTK 9.1's VolumePreservation gave bit-identical output on the phantom, so it runs without);
#   3. segmesh_decimation_peers: segmesh (error and budget), meshopt_simplify and
#      meshopt_simplifySloppy per part, and the VTK folder, all scored against the
#      undecimated parts with the library's measures.
#   bench/compare_decimation.sh [BUILD_DIR] [OUT_DIR] [LABEL_MAP]
# LABEL_MAP: any label map instead of the phantom (e.g. a pelvic fracture mask of ../shared/data).
# Needs the build's segmesh and segmesh_decimation_peers (built when Debian's libmeshoptimizer-dev
# is installed) and python3-vtk9: scripts/install-deps.sh --with-peers. About two minutes on two
# cores; run it on a quiet machine.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(dirname "$here")"
build="${1:-$repo/build}"
out="${2:-$(mktemp -d /tmp/segmesh_decimation.XXXXXX)}"
mkdir -p "$out"
segmesh="$build/apps/cli/segmesh"
peers="$build/bench/segmesh_decimation_peers"
[[ -x "$peers" ]] || { echo "no $peers: install libmeshoptimizer-dev, reconfigure and build it" >&2; exit 1; }
py=/usr/bin/python3

input="${3:-$out/phantom.nii.gz}"
[[ -n "${3:-}" || -f "$input" ]] || "$segmesh" phantom -o "$input" --quiet
rm -rf "$out/undecimated" "$out/segmesh_0.2" "$out/vtk"
"$segmesh" mesh "$input" -o "$out/undecimated/" --quiet
"$segmesh" mesh "$input" -o "$out/segmesh_0.2/" --decimate-error 0.2 --quiet
vtk=$($py "$here/vtk_decimate.py" "$out/undecimated" "$out/segmesh_0.2" "$out/vtk")
echo "vtk_decimate.py: $vtk" >&2
seconds=$($py -c 'import json, sys; print(json.loads(sys.argv[1])["seconds"])' "$vtk")
"$peers" "$input" --peer "vtkQuadricDecimation" "$out/vtk" "$seconds"
echo
echo "segmesh $(git -C "$repo" rev-parse --short HEAD), $(date -u +%Y-%m-%d), $(nproc) cores, output in $out"
