#!/usr/bin/env bash
# The layout rules of docs/ARCHITECTURE.md, checked on the source tree:
#  1. no source file in src/, apps/ or python/ is longer than 600 lines, unless its first five
#     lines say "exempt from the 600-line limit" and why (generated or literal tables);
#  2. machinery stays inside its library: no file in apps/ or python/ and no public header
#     (src/<library>/*.hpp) includes a detail/ header; tests/ and bench/, which check and
#     measure the machinery, may;
#  3. no detail/ header of one library is included by another library, except the ones listed in
#     ALLOWED below.
# Prints every violation and exits 1 when there is one.
#   tests/layout/check_layout.sh [SOURCE_DIR]
set -u
root=${1:-$(cd "$(dirname "$0")/../.." && pwd)}
cd "$root" || exit 2
status=0
fail() { echo "layout: $*"; status=1; }

while IFS= read -r f; do
  n=$(wc -l < "$f")
  if ((n > 600)) && ! head -n 5 "$f" | grep -q 'exempt from the 600-line limit'; then
    fail "$f has $n lines (at most 600; split it by what its pieces do)"
  fi
done < <(find src apps $([[ -d python ]] && echo python) -type f \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' \) | sort)

detail_include='#include *"segmesh[a-z_]*/detail/'
for dir in apps python; do
  [[ -d $dir ]] || continue
  while IFS= read -r hit; do fail "$hit: $dir/ includes library machinery (a detail/ header)"; done \
    < <(grep -rnE "$detail_include" "$dir" --include='*.cpp' --include='*.hpp' || true)
done
while IFS= read -r hit; do fail "$hit: a public header includes a detail/ header"; done \
  < <(grep -nE "$detail_include" src/*/*.hpp || true)

ALLOWED=()
for lib in src/*/; do
  lib=${lib%/}
  name=${lib#src/}
  while IFS= read -r hit; do
    file=${hit%%:*}
    header=$(sed -E 's/.*#include *"([^"]+)".*/\1/' <<<"${hit#*:*:}")
    owner=${header%%/*}
    [[ $owner == "$name" ]] && continue
    allowed=0
    for a in "${ALLOWED[@]+"${ALLOWED[@]}"}"; do [[ $a == "$header" ]] && allowed=1; done
    ((allowed)) || fail "$file includes $header, machinery of another library"
  done < <(grep -rnE "$detail_include" "$lib" --include='*.cpp' --include='*.hpp' || true)
done
((status == 0)) && echo "layout: ok"
exit $status
