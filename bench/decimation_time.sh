#!/usr/bin/env bash
# Decimation time against extraction time, as users run it (issue 36's time target: decimating
# the 5.4 M-triangle scene to 1 % at 2 threads in under twice its extraction time). Runs
# `segmesh mesh INPUT -o OUT/x.glb OPTIONS --report r.json` for each binary given (e.g. an old
# build's segmesh copied aside, then the current one), alternating them over ROUNDS rounds, and
# prints one Markdown row per binary: the report's timings_ms (decimate, extract), their ratio,
# triangles, the largest Hausdorff distance of the parts' decimation, all parts closed and
# manifold, and the triangle-weighted mean radii ratio; medians of the times over the rounds.
#
#   bench/decimation_time.sh OUT_DIR INPUT "OPTIONS" SEGMESH [SEGMESH ...]
#   bench/decimation_time.sh /tmp/dt phantom.nii.gz "--decimate-error 0.2" /tmp/old build/apps/cli/segmesh
#   bench/decimation_time.sh /tmp/dt big_seg.nii.gz "--max-triangles 50000" build/apps/cli/segmesh
#
# ROUNDS (default 1) and THREADS (default 2, passed as --threads). The times are wall times of
# the steps: run it on a quiet machine, or say how loaded it was (`uptime` is printed).
set -euo pipefail
if (($# < 4)); then
  echo "usage: bench/decimation_time.sh OUT_DIR INPUT \"OPTIONS\" SEGMESH [SEGMESH ...]" >&2
  exit 2
fi
out=$1 input=$2 options=$3
shift 3
rounds=${ROUNDS:-1}
threads=${THREADS:-2}
mkdir -p "$out"

for ((r = 0; r < rounds; ++r)); do
  for ((b = 1; b <= $#; ++b)); do
    # shellcheck disable=SC2086 # OPTIONS is a list of options
    "${!b}" mesh "$input" -o "$out/x$b.glb" $options --threads "$threads" \
      --report "$out/r${b}_$r.json" --quiet
  done
done

/usr/bin/python3 - "$out" "$rounds" "$input" "$options" "$@" <<'EOF'
import json, statistics, sys
out, rounds, input_, options, binaries = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4], sys.argv[5:]
print(f"input {input_}, options {options}")
print("| segmesh | decimate (s) | extract (s) | decimate / extract | triangles | Hausdorff max (mm) "
      "| all closed | mean radii ratio |")
print("| --- | ---: | ---: | ---: | ---: | ---: | --- | ---: |")
for b, binary in enumerate(binaries, start=1):
    reports = [json.load(open(f"{out}/r{b}_{r}.json")) for r in range(rounds)]
    dec = statistics.median(r["timings_ms"]["decimate"] for r in reports) / 1000
    ext = statistics.median(r["timings_ms"]["extract"] for r in reports) / 1000
    parts = reports[-1]["parts"]
    tris = sum(p["triangles"] for p in parts)
    haus = max(p.get("decimation", {}).get("hausdorff_mm", 0) for p in parts)
    closed = all(p["closed"] and p["nonmanifold_edges"] == 0 for p in parts)
    rho = sum(p["radii_ratio"]["mean"] * p["triangles"] for p in parts) / tris
    print(f"| {binary} | {dec:.2f} | {ext:.3f} | {dec / ext:.0f} | {tris} | {haus:.3f} | "
          f"{'yes' if closed else 'no'} | {rho:.3f} |")
EOF
echo "$(nproc) cores, $(uptime)"
