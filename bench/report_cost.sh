#!/usr/bin/env bash
# What `--report` costs: the same `segmesh mesh` command with and without it, alternated in one
# run, wall time and peak memory (maximum resident set) of each, and their ratios; and how much of
# the wall time the report's own timings_ms account for (their total against the wall).
#
#   bench/report_cost.sh BUILD_DIR OUT_DIR INPUT [INPUT ...]
#   ROUNDS=5 EXTRA="--smooth hc --iterations 2" bench/report_cost.sh build /tmp/rc big_seg.nii.gz
#
# Each round runs both commands back to back (the order alternates); the table gives medians over
# ROUNDS (default 3). EXTRA holds meshing options for both (default: none, the defaults, as
# `make demo` runs). THREADS (default 2) is passed as --threads.
set -euo pipefail
if (($# < 3)); then
  echo "usage: bench/report_cost.sh BUILD_DIR OUT_DIR INPUT [INPUT ...]" >&2
  exit 2
fi
build=$1 out=$2
shift 2
segmesh="$build/apps/cli/segmesh"
rounds=${ROUNDS:-3}
threads=${THREADS:-2}
extra=${EXTRA:-}
mkdir -p "$out"

# One run: prints "seconds peak_kb".
run() {
  /usr/bin/python3 - "$@" <<'EOF'
import resource, subprocess, sys, time
start = time.perf_counter()
r = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL)
wall = time.perf_counter() - start
if r.returncode != 0:
    sys.exit("segmesh failed: " + " ".join(sys.argv[1:]))
print(f"{wall:.4f} {resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss}")
EOF
}

median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }

printf "| input | options | without: s | with: s | time ratio | without: MB | with: MB | memory ratio | report total / wall |\n"
printf "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n"
for input in "$@"; do
  name=$(basename "$input")
  plain_t=() plain_m=() rep_t=() rep_m=() cover=()
  for ((r = 0; r < rounds; ++r)); do
    rm -f "$out/plain.glb" "$out/rep.glb" "$out/r.json"
    # shellcheck disable=SC2086
    cmd_plain=("$segmesh" mesh "$input" -o "$out/plain.glb" --threads "$threads" $extra)
    # shellcheck disable=SC2086
    cmd_rep=("$segmesh" mesh "$input" -o "$out/rep.glb" --report "$out/r.json" --threads "$threads" $extra)
    if ((r % 2 == 0)); then
      read -r t m < <(run "${cmd_plain[@]}")
      read -r rt rm_ < <(run "${cmd_rep[@]}")
    else
      read -r rt rm_ < <(run "${cmd_rep[@]}")
      read -r t m < <(run "${cmd_plain[@]}")
    fi
    plain_t+=("$t") plain_m+=("$m") rep_t+=("$rt") rep_m+=("$rm_")
    total_ms=$(/usr/bin/python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['timings_ms']['total'])" "$out/r.json")
    cover+=("$(awk -v a="$total_ms" -v b="$rt" 'BEGIN {print a / 1000 / b}')")
    rm -f "$out/plain.glb" "$out/rep.glb"
  done
  pt=$(printf "%s\n" "${plain_t[@]}" | median)
  rt=$(printf "%s\n" "${rep_t[@]}" | median)
  pm=$(printf "%s\n" "${plain_m[@]}" | median)
  rm_=$(printf "%s\n" "${rep_m[@]}" | median)
  cv=$(printf "%s\n" "${cover[@]}" | median)
  awk -v n="$name" -v o="${extra:-defaults}" -v pt="$pt" -v rt="$rt" -v pm="$pm" -v rm="$rm_" -v cv="$cv" \
    'BEGIN {printf "| %s | %s | %.2f | %.2f | %.2fx | %.0f | %.0f | %.2fx | %.2f |\n", n, o, pt, rt, rt / pt, pm / 1024, rm / 1024, rm / pm, cv}'
done
