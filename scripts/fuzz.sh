#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/, clang, AddressSanitizer + UndefinedBehaviorSanitizer) in
# build-fuzz, seeds a corpus per target from ../shared/data, the built-in phantom and fuzz/seeds/,
# and runs each target for a set time. Findings (crash-*, leak-*, timeout-*, oom-*) land in
# build-fuzz/artifacts/<target>/; the script ends non-zero when there are any.
#
#   scripts/fuzz.sh                 every target for 60 s
#   scripts/fuzz.sh 300             every target for 300 s
#   scripts/fuzz.sh 60 nifti dicom  only these targets (names without "fuzz_")
#
# Environment: JOBS (build parallelism, default 2), SEGMESH (a segmesh executable for the phantom
# seeds; default build-robust/apps/cli/segmesh or build/apps/cli/segmesh, else they are skipped),
# FUZZ_ARGS (extra libFuzzer flags). Needs clang and libclang-rt-14-dev:
# scripts/install-deps.sh --with-fuzz.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
seconds=${1:-60}
shift || true
build=build-fuzz
jobs=${JOBS:-2}
data=${SEGMESH_DATA_DIR:-$root/../shared/data}

all_targets=(nifti nrrd seg_nrrd mha mrc dicom stl ply obj glb label_names)
targets=("$@")
if ((${#targets[@]} == 0)); then targets=("${all_targets[@]}"); fi

if ! command -v clang++ >/dev/null; then
  echo "fuzz: clang++ not found; run scripts/install-deps.sh --with-fuzz" >&2
  exit 2
fi
if [[ ! -f $build/build.ninja ]]; then
  CC=clang CXX=clang++ cmake -S . -B $build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DSEGMESH_FUZZ=ON -DSEGMESH_BUILD_TESTS=OFF >/dev/null
fi
cmake --build $build -j "$jobs" --target $(printf 'fuzz_%s ' "${targets[@]}")

# --- seeds -------------------------------------------------------------------------------------
corpus=$build/corpus
seeds=$build/seeds   # generated, read-only inputs to each run (the corpus dir is what grows)
mkdir -p "$corpus" "$seeds" "$build/artifacts"
segmesh=${SEGMESH:-}
for candidate in build-robust/apps/cli/segmesh build/apps/cli/segmesh; do
  if [[ -z $segmesh && -x $candidate ]]; then segmesh=$candidate; fi
done

seed_dir() { mkdir -p "$seeds/$1" && echo "$seeds/$1"; }
copy_small() {  # copy_small TARGET FILE... : files under 200 kB
  local dir
  dir=$(seed_dir "$1")
  shift
  for f in "$@"; do
    if [[ -f $f && $(stat -c %s "$f") -lt 200000 ]]; then cp -f "$f" "$dir/"; fi
  done
}
if [[ ! -f $seeds/.done ]]; then
  echo "fuzz: generating seeds in $seeds"
  for t in "${all_targets[@]}"; do seed_dir "$t" >/dev/null; done
  if [[ -d $data ]]; then
    copy_small nifti "$data"/totalsegmentator/example_seg.nii.gz
    copy_small nrrd "$data"/dcmqi/*.nrrd
    copy_small mrc "$data"/mrc/EMD-3197.map
    copy_small label_names "$data"/totalsegmentator/labels.tsv
    # Two neighbouring slices of the head CT as one input (see fuzz/fuzz_dicom.cpp), and single
    # slices (a folder of one).
    head=$data/slicer_ct_head/CTHeadAxialDicom
    if [[ -d $head ]]; then
      cp -f "$head/CTHead10.dcm" "$seeds/dicom/one.dcm"
      python3 - "$head/CTHead10.dcm" "$head/CTHead11.dcm" "$seeds/dicom/two" <<'EOF'
import struct, sys
a = open(sys.argv[1], 'rb').read(); b = open(sys.argv[2], 'rb').read()
open(sys.argv[3], 'wb').write(b'SEGMESH2' + struct.pack('<I', len(a)) + a + b)
EOF
    fi
  fi
  if [[ -n $segmesh ]]; then
    tmp=$(mktemp -d)
    "$segmesh" phantom -o "$tmp/p.nii" --size 24,24,8 --spacing 4,4,25 >/dev/null
    "$segmesh" phantom -o "$tmp/p.nii.gz" --size 24,24,8 --spacing 4,4,25 >/dev/null
    "$segmesh" phantom -o "$tmp/p.nrrd" --size 24,24,8 --spacing 4,4,25 >/dev/null
    "$segmesh" phantom -o "$tmp/p.mha" --size 24,24,8 --spacing 4,4,25 >/dev/null
    cp "$tmp/p.nii" "$tmp/p.nii.gz" "$seeds/nifti/"
    cp "$tmp/p.nrrd" "$seeds/nrrd/"
    cp "$tmp/p.mha" "$seeds/mha/"
    for fmt in stl ply obj glb; do
      "$segmesh" mesh "$tmp/p.nii" -o "$tmp/p.$fmt" --smooth none --quiet >/dev/null
      cp "$tmp/p.$fmt" "$seeds/$fmt/"
    done
    rm -rf "$tmp"
  else
    echo "fuzz: no segmesh executable found (build one or set SEGMESH); no phantom seeds" >&2
  fi
  touch "$seeds/.done"
fi

# --- runs --------------------------------------------------------------------------------------
# Leaks inside prebuilt third-party libraries only (each entry says why).
export LSAN_OPTIONS="suppressions=$root/fuzz/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
found=0
for t in "${targets[@]}"; do
  mkdir -p "$corpus/$t" "$build/artifacts/$t"
  dirs=("$corpus/$t" "$seeds/$t")
  [[ -d fuzz/seeds/$t ]] && dirs+=("fuzz/seeds/$t")
  dict=()
  [[ -f fuzz/dict/$t.dict ]] && dict=(-dict="fuzz/dict/$t.dict")
  echo "fuzz: $t for ${seconds}s"
  set +e
  "$build/fuzz/fuzz_$t" "${dirs[@]}" "${dict[@]}" -max_total_time="$seconds" -timeout=10 \
    -rss_limit_mb=2048 -max_len=262144 -print_final_stats=1 \
    -artifact_prefix="$build/artifacts/$t/" ${FUZZ_ARGS:-} >"$build/artifacts/$t.log" 2>&1
  status=$?
  set -e
  grep -E "^stat::number_of_executed_units|^stat::peak_rss_mb" "$build/artifacts/$t.log" |
    sed "s/^/fuzz: $t: /" || true
  n=$(find "$build/artifacts/$t" -type f | wc -l)
  if ((status != 0 || n > 0)); then
    echo "fuzz: $t: FINDINGS (exit $status, $n artifacts in $build/artifacts/$t, log $build/artifacts/$t.log)"
    found=1
  fi
done
exit $found
