#!/usr/bin/env bash
# The pictures of the two-robot cell's nets in docs/workcell.md (docs/img/*.svg), rendered from the scripts:
# the cell program writes each net as Graphviz DOT (`--net-dot`, examples/workcell/two_robots/
# net_picture.hpp) and Graphviz's `dot` (Debian package graphviz) lays it out. A docs step, run by hand
# after a net changes — ctest does not need Graphviz.
#
#   bash scripts/net-pictures.sh [BUILD_DIR]      (default: build; the program must be built there)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build}"
program="$build/examples/vsd_two_robot_cell"
[[ -x "$program" ]] || { echo "net-pictures: $program is not built (cmake --build $build --target vsd_two_robot_cell)" >&2; exit 1; }
command -v dot >/dev/null || { echo "net-pictures: Graphviz's dot is not installed (apt-get install graphviz)" >&2; exit 1; }
mkdir -p "$root/docs/img"
for net in meta_control multi_robot_control; do
  out="$root/docs/img/$net.svg"
  "$program" --net-dot "$root/examples/workcell/$net.soml" | dot -Tsvg > "$out.tmp"
  mv "$out.tmp" "$out"
  echo "wrote $out"
done
