#!/usr/bin/env bash
# Conforming surfaces against independent ones and against VTK on the same label maps: one table
# with, per map and tool, the time (and its ratio to VTK's in the same run), the triangles, whether
# every part is closed and manifold, the volume error, and the contact quality between touching
# labels (the distance between the two sides of each contact after smoothing, and the triangles of
# one label crossing the other's). The tools:
#   segmesh mesh MAP -o DIR/                         conforming surfaces (the default)
#   segmesh mesh MAP -o DIR/ --surfaces independent  every part on its own
#   VTK vtkDiscreteFlyingEdges3D + vtkWindowedSincPolyDataFilter per label, 3D Slicer's settings
#     through ../shared/tools/peer_mesh.py (Debian's VTK 9.1 has no vtkSurfaceNets3D, the filter
#     newer Slicer can use for exactly this)
# Definitions: bench/conforming_vtk_table.py. Maps: the built-in phantom, the pelvic fragments of
# cases 001 and 002 (left hip), both TotalSegmentator maps of ../shared/data and big_seg (54 parts
# that touch nowhere: time and shape only).
#
#   bench/compare_conforming_vtk.sh [BUILD_DIR] [OUT_DIR]
#
# THREADS (default 2) for segmesh's --threads and vtkSMPTools; REPEATS (default 3): times are the
# best of that many runs. BIG_SEG: big_seg.nii.gz if built already (otherwise made here with
# ../shared/tools/make_big.py). Takes about 5 minutes on 2 cores.
# Needs Debian's python3-vtk9 python3-nibabel python3-numpy python3-scipy
# (scripts/install-deps.sh --with-peers).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(dirname "$here")"
build="${1:-$repo/build}"
out="${2:-$(mktemp -d /tmp/segmesh_conforming_vtk.XXXXXX)}"
shared="$repo/../shared"
py=/usr/bin/python3
segmesh="$build/apps/cli/segmesh"

fail() { echo "compare_conforming_vtk.sh: $*" >&2; exit 2; }
[[ -x "$segmesh" ]] || fail "missing $segmesh: build the target segmesh first"
[[ -x "$py" ]] || fail "missing $py (Debian's python3)"
for tool in peer_mesh.py mesh_metrics.py make_big.py; do
  [[ -f "$shared/tools/$tool" ]] || fail "missing $shared/tools/$tool"
done
for module in vtk nibabel numpy scipy; do
  $py -c "import $module" 2>/dev/null ||
    fail "python module $module missing: apt-get install -y python3-vtk9 python3-nibabel python3-numpy python3-scipy"
done
command -v git >/dev/null || fail "missing git"
mkdir -p "$out"

maps=("$out/phantom.nii.gz")
[[ -f "$out/phantom.nii.gz" ]] || "$segmesh" phantom -o "$out/phantom.nii.gz" --quiet
for map in pelvic_fracture/001/001_LI_mask.nii.gz pelvic_fracture/002/002_LI_mask.nii.gz \
  totalsegmentator/example_seg.nii.gz totalsegmentator/example_seg_dicom.nii.gz; do
  [[ -f "$shared/data/$map" ]] || fail "missing $shared/data/$map"
  maps+=("$shared/data/$map")
done
big="${BIG_SEG:-$out/big_seg.nii.gz}"
[[ -f "$big" ]] ||
  $py "$shared/tools/make_big.py" "$shared/data/totalsegmentator/example_seg_dicom.nii.gz" "$big" >/dev/null
maps+=("$big")

threads="${THREADS:-2}"
echo "$(date -u '+%Y-%m-%d %H:%M UTC'), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'),"\
  "$(nproc) cores, load $(cut -d' ' -f1 /proc/loadavg); segmesh $(git -C "$repo" rev-parse --short HEAD),"\
  "VTK $($py -c 'import vtk; print(vtk.vtkVersion.GetVTKVersion())'), $threads threads"
echo
$py "$here/conforming_vtk_table.py" --segmesh "$segmesh" --out "$out" --threads "$threads" \
  --repeats "${REPEATS:-3}" "${maps[@]}"
echo
echo "files in $out"
