#!/usr/bin/env bash
# segmesh against the peers users pick today, on the same inputs in one go, as time ratios per step
# at 1 and 2 threads:
#   extraction   segmesh Marching Cubes of every part   vs  VTK vtkDiscreteFlyingEdges3D (3D Slicer)
#                (VTK gets each label cropped to its box, untimed; segmesh's components, a step
#                VTK does not have, are timed on their own and shown added too)
#   Dual Contouring                                     vs  segmesh's own Marching Cubes
#   smoothing    segmesh HC x2 and default smoothing    vs  VTK windowed sinc, 20 iterations (Slicer)
#                and, as Slicer runs it, the sinc plus vtkPolyDataNormals (bench/slicer_normals.py:
#                segmesh's smoothing recomputes the normals within its time, VTK's sinc does not)
#   whole        `segmesh mesh IN -o OUT.glb --smooth hc --iterations 2` wall time and peak memory
# Inputs: the big 512x512x203 volume from ../shared/tools/make_big.py, the 512x512x203 phantom and
# ../shared/data/pelvic_fracture/001 (the left hip fragments).
#   bench/compare_peers.sh [BUILD_DIR] [OUT_DIR]
# ROUNDS=N (default 1) repeats each pair of runs N times; Table 1's columns are then the medians
# of the times and of the ratios taken within each round.
# Needs Debian's python3-vtk9 python3-nibabel python3-numpy python3-scipy (scripts/install-deps.sh
# --with-peers). Takes a few minutes; run it on a quiet machine.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(dirname "$here")"
build="${1:-$repo/build}"
out="${2:-$(mktemp -d /tmp/segmesh_peers.XXXXXX)}"
shared="$repo/../shared"
mkdir -p "$out"
py=/usr/bin/python3
rounds="${ROUNDS:-1}"

inputs=()
if [[ -f "$shared/tools/make_big.py" ]]; then
  [[ -f "$out/big_seg.nii.gz" ]] ||
    $py "$shared/tools/make_big.py" "$shared/data/totalsegmentator/example_seg_dicom.nii.gz" \
      "$out/big_seg.nii.gz" >/dev/null
  inputs+=("$out/big_seg.nii.gz")
fi
[[ -f "$out/phantom.nii.gz" ]] || "$build/apps/cli/segmesh" phantom -o "$out/phantom.nii.gz" --quiet
inputs+=("$out/phantom.nii.gz")
[[ -f "$shared/data/pelvic_fracture/001/001_LI_mask.nii.gz" ]] &&
  inputs+=("$shared/data/pelvic_fracture/001/001_LI_mask.nii.gz")

echo "| input | threads | VTK discrete FE (s) | segmesh MC (s) | VTK / MC | segmesh components (s) | VTK / (components + MC) | segmesh DC (s) | DC / MC | segmesh HC x2 (s) | VTK sinc x20 (s) | sinc / HC x2 | segmesh default smoothing (s) | sinc / default | VTK normals (s) | (sinc + normals) / HC x2 |"
echo "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
for input in "${inputs[@]}"; do
  name=$(basename "$input")
  for t in 1 2; do
    # VTK and segmesh at the same thread count back to back, ROUNDS times: the host's load drifts
    # over minutes, so each ratio is taken within one round and the table shows the medians.
    for round in $(seq "$rounds"); do
      rm -f "$out/$name.vtk.$t.$round.jsonl"  # peer_mesh.py appends to its --json file
      $py "$shared/tools/peer_mesh.py" "$input" --methods vtk_discrete_flying_edges,vtk_discrete_flying_edges_sinc \
        --threads "$t" --repeats 3 --json "$out/$name.vtk.$t.$round.jsonl" >/dev/null 2>&1
      $py "$here/slicer_normals.py" "$input" --threads "$t" --repeats 3 > "$out/$name.normals.$t.$round.json"
      "$build/bench/segmesh_step_timing" "$input" "$t" 3 > "$out/$name.segmesh.$t.$round.json"
    done
    $py - "$out" "$name" "$t" "$rounds" <<'PY'
import json, statistics, sys
out, name, t, rounds = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
cols = {}
for r in range(1, rounds + 1):
    extract = sinc = 0.0
    for line in open(f"{out}/{name}.vtk.{t}.{r}.jsonl"):
        d = json.loads(line)
        if d["method"] == "vtk_discrete_flying_edges":
            extract += d["extract_s"][t]
        if d["method"] == "vtk_discrete_flying_edges_sinc":
            sinc += d["smooth_s"][t]
    o = json.load(open(f"{out}/{name}.segmesh.{t}.{r}.json"))
    normals = json.load(open(f"{out}/{name}.normals.{t}.{r}.json"))["normals_s"]
    mc, comp, dc, hc, smooth = o["mc_s"], o["components_s"], o["dc_s"], o["hc2_s"], o["default_smooth_s"]
    row = {"extract": extract, "mc": mc, "vtk/mc": extract / mc, "comp": comp,
           "vtk/(comp+mc)": extract / (comp + mc), "dc": dc, "dc/mc": dc / mc, "hc": hc,
           "sinc": sinc, "sinc/hc": sinc / hc, "smooth": smooth, "sinc/smooth": sinc / smooth,
           "normals": normals, "slicer/hc": (sinc + normals) / hc}
    for k, v in row.items():
        cols.setdefault(k, []).append(v)
m = {k: statistics.median(v) for k, v in cols.items()}
print(f"| {name} | {t} | {m['extract']:.4f} | {m['mc']:.4f} | {m['vtk/mc']:.2f}x | {m['comp']:.4f} | "
      f"{m['vtk/(comp+mc)']:.2f}x | {m['dc']:.4f} | {m['dc/mc']:.2f} | {m['hc']:.4f} | "
      f"{m['sinc']:.3f} | {m['sinc/hc']:.1f}x | {m['smooth']:.3f} | {m['sinc/smooth']:.1f}x | "
      f"{m['normals']:.3f} | {m['slicer/hc']:.1f}x |")
PY
  done
done
echo
echo "| input | whole segmesh mesh -> GLB, HC x2 (wall s) | peak memory (MB) | input voxels + mesh bytes (MB) | peak / that |"
echo "| --- | ---: | ---: | ---: | ---: |"
for input in "${inputs[@]}"; do
  name=$(basename "$input")
  best=1e9; peak=0
  for r in 1 2 3; do
    # Each run writes a new file with no dirty file data pending: replacing the previous run's
    # 97 MB output, still being written back, added 50-130 ms to the write step on the test VM
    # (file-system work, not segmesh's; docs/PERFORMANCE.md).
    rm -f "$out/$name.glb"
    sync
    /usr/bin/time -f "%e %M" -o "$out/time.txt" "$build/apps/cli/segmesh" mesh "$input" -o "$out/$name.glb" \
      --smooth hc --iterations 2 --quiet
    read -r wall kb < "$out/time.txt"
    best=$($py -c "print(min($best, $wall))")
    peak=$kb
  done
  # Sizes for the memory budget, from a report (not timed: the report measures deviations).
  "$build/apps/cli/segmesh" mesh "$input" -o "$out/$name.glb" --smooth hc --iterations 2 --quiet \
    --report "$out/$name.report.json"
  $py - "$out/$name.report.json" "$best" "$peak" "$name" <<'PY'
import json, sys
report, wall, peak_kb, name = sys.argv[1], float(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
r = json.load(open(report))
d = r["input"]["dims"]
voxels = d[0] * d[1] * d[2]
bytes_per_voxel = {"uint8": 1, "int8": 1, "uint16": 2, "int16": 2}.get(r["input"]["type"], 4)
mesh = r["totals"]["vertices"] * 24 + r["totals"]["triangles"] * 12
base = (voxels * bytes_per_voxel + mesh) / 1e6
print(f"| {name} | {wall:.2f} | {peak_kb / 1024:.0f} | {base:.0f} | {peak_kb / 1024 / base:.2f} |")
PY
done
echo
echo "files in $out"
