#!/usr/bin/env bash
# Installs every Debian package segmesh's build, tests and demo need, and the npm tools the tests
# use (the Khronos glTF validator). Idempotent: does nothing when everything is present.
# Uses sudo only when not root.
#   scripts/install-deps.sh              build, test and demo dependencies
#   scripts/install-deps.sh --with-peers also the Python/VTK/scikit-image/meshoptimizer peers used by bench/
#   scripts/install-deps.sh --with-fuzz  also clang and libFuzzer (scripts/fuzz.sh, fuzz/)
# (the flags combine: --with-peers --with-fuzz)
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  cmake ninja-build g++ make pkg-config git     # build
  ccache                                        # compiler cache: fresh clones rebuild from it
  libinsighttoolkit5-dev zlib1g-dev             # volume formats (NIfTI, NRRD, MHA, DICOM)
  libtbb-dev                                    # threads (oneTBB)
  libjemalloc-dev                               # the programs' malloc, with huge pages (src/segmesh_alloc)
  libcli11-dev nlohmann-json3-dev               # command line, JSON (reports, glTF)
  googletest libgtest-dev python3-numpy python3-scipy  # tests (../shared/tools/mesh_metrics.py)
  libdeflate-dev                                # fast gzip inflate (.nii.gz, .seg.nrrd)
  libgdcm-dev                                   # GDCM: DICOM warnings silenced (dicom_series.cpp), its data dictionary (dicom_file_check.cpp)
  libbenchmark-dev                              # Google Benchmark (bench/segmesh_bench)
  libepoxy-dev libegl-dev libstb-dev            # renderer: OpenGL/EGL loader, EGL headers, PNG
  libegl-mesa0 libgl1-mesa-dri                  # headless rendering: Mesa's EGL and llvmpipe
  libglfw3-dev libimgui-dev libglx-mesa0        # segmesh-viewer: window, Dear ImGui, GLX
  xvfb xauth                                    # the viewer's smoke test runs it under xvfb-run
  pybind11-dev python3-dev                      # the Python package (python/, docs/PYTHON.md)
  python3-nibabel                               # its tests: nibabel images against the CLI
  python3-dask python3-distributed              # python3 -m segmesh.batch: cohorts on a Dask cluster (docs/COHORTS.md)
)
for flag in "$@"; do
  case "$flag" in
    --with-peers) packages+=(python3-vtk9 python3-skimage python3-numpy python3-nibabel python3-scipy
                             libmeshoptimizer-dev) ;;  # bench/compare_decimation.sh
    --with-fuzz) packages+=(clang libclang-rt-14-dev) ;;  # libFuzzer and the sanitizer runtimes
    *) echo "install-deps: unknown option $flag (use --with-peers, --with-fuzz)" >&2; exit 2 ;;
  esac
done
# Node.js and npm run the glTF validator in the tests; a machine may already have its own.
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  packages+=(nodejs npm)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then sudo_cmd=(sudo); fi

if ((${#missing[@]})); then
  echo "install-deps: installing ${missing[*]}"
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends \
    "${missing[@]}" >/dev/null
fi

# npm tools, pinned by tools/npm/package-lock.json.
if [[ ! -f tools/npm/node_modules/gltf-validator/package.json ]]; then
  echo "install-deps: installing the glTF validator (npm)"
  (cd tools/npm && npm ci --no-audit --no-fund --loglevel=error >/dev/null)
fi
echo "install-deps: all dependencies present"
