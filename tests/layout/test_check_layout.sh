#!/usr/bin/env bash
# check_layout.sh finds each kind of violation in a small tree made for it, and passes a clean one.
set -u
checker="$(cd "$(dirname "$0")" && pwd)/check_layout.sh"
tree=$(mktemp -d)
trap 'rm -rf "$tree"' EXIT
mkdir -p "$tree"/src/segmesh/detail "$tree"/src/segmesh_io "$tree"/apps/cli
echo '#pragma once' > "$tree"/src/segmesh/detail/machinery.hpp
echo '#include "segmesh/detail/machinery.hpp"' > "$tree"/src/segmesh/algorithm.cpp
echo '#pragma once' > "$tree"/src/segmesh/algorithm.hpp
echo 'int main() {}' > "$tree"/apps/cli/main.cpp
out=$("$checker" "$tree") || { echo "clean tree refused: $out"; exit 1; }

expect() {  # expect MESSAGE: the checker fails and says MESSAGE
  local out
  if out=$("$checker" "$tree"); then echo "not found: $1"; exit 1; fi
  grep -q "$1" <<<"$out" || { echo "expected '$1' in: $out"; exit 1; }
}
seq 1 601 > "$tree"/src/segmesh/long.cpp
expect "long.cpp has 601 lines"
{ echo '// A literal table: exempt from the 600-line limit.'; seq 1 700; } > "$tree"/src/segmesh/long.cpp
out=$("$checker" "$tree") || { echo "exempt file refused: $out"; exit 1; }
echo '#include "segmesh/detail/machinery.hpp"' >> "$tree"/apps/cli/main.cpp
expect "apps/ includes library machinery"
echo 'int main() {}' > "$tree"/apps/cli/main.cpp
echo '#include "segmesh/detail/machinery.hpp"' >> "$tree"/src/segmesh/algorithm.hpp
expect "a public header includes a detail/ header"
echo '#pragma once' > "$tree"/src/segmesh/algorithm.hpp
echo '#include "segmesh/detail/machinery.hpp"' > "$tree"/src/segmesh_io/reader.cpp
expect "machinery of another library"
echo "check_layout finds every violation"
