#!/usr/bin/env bash
# Builds and runs the main vsd demo: the paper's two-robot work cell (examples/workcell/two_robots,
# docs/workcell.md), two 8-axis robots under the SOML++ nets meta_control.soml and
# multi_robot_control.soml. When a module it needs was skipped at configure time (a missing Debian
# package), the core-only tour (examples/demo) runs instead, and says so.
#   bash scripts/demo.sh            the two-robot cell, 20 parts; further arguments go to it
#                                   (--seed N, --parts N, --csv FILE, --quiet, ...)
#   bash scripts/demo.sh --one-robot  the smaller one-robot cell (examples/workcell: writes workcell.csv,
#                                   and workcell.png with gnuplot, into build/examples/workcell)
#   bash scripts/demo.sh --tour     the core-only tour (examples/demo); further arguments go to it
# It installs only what it runs (scripts/install-deps.sh, groups): the work cell needs the core, vsd::scene
# (urdfdom, assimp), vsd::collision (FCL, libccd) and vsd::physics (ODE); the tour the core only. With
# --serve [PORT] (either cell, docs/web.md) it adds the `web` group and builds the page (vsd_web_assets). gnuplot
# (for the one-robot cell's PNG) is not installed: that cell writes its CSV without it. The tests are not
# configured.
# Environment: BUILD_DIR (default build), VSD_SKIP_DEPS=1 to skip the dependency check.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

BUILD_DIR="${BUILD_DIR:-build}"

serve=0
for a in "$@"; do [[ "$a" == "--serve" ]] && serve=1; done
if [[ "${1:-}" == "--tour" ]]; then
  bash scripts/install-deps.sh core
elif [[ $serve -eq 1 ]]; then   # the cell in the browser: vsd::web and its page (npm) too
  bash scripts/install-deps.sh core scene collision physics web
else
  bash scripts/install-deps.sh core scene collision physics
fi
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DVSD_BUILD_TESTS=OFF

tour() {
  cmake --build "$BUILD_DIR" --target vsd_demo --parallel 2
  "$BUILD_DIR/examples/vsd_demo" "$@"
}

if [[ "${1:-}" == "--tour" ]]; then
  shift
  tour "$@"
  exit
fi
# The work cells exist only when vsd::soml, ::robotics, ::physics and ::collision were all configured.
# (The target list is read whole first: `grep -q` would stop reading early, and under pipefail the
# writer's SIGPIPE would count as "not found".)
targets="$(cmake --build "$BUILD_DIR" --target help)"
if [[ $serve -eq 1 ]] && grep -q '\bvsd_web_assets\b' <<<"$targets"; then
  cmake --build "$BUILD_DIR" --target vsd_web_assets
fi
if [[ "${1:-}" == "--one-robot" ]] && grep -q '\bvsd_workcell\b' <<<"$targets"; then
  shift
  cmake --build "$BUILD_DIR" --target vsd_workcell --parallel 2
  mkdir -p "$BUILD_DIR/examples/workcell"
  "$BUILD_DIR/examples/vsd_workcell" tests/scene/data/iiwa14.urdf examples/workcell/workcell.soml \
    "$BUILD_DIR/examples/workcell" "$@"
elif grep -q '\bvsd_two_robot_cell\b' <<<"$targets"; then
  [[ "${1:-}" == "--one-robot" ]] && shift
  cmake --build "$BUILD_DIR" --target vsd_two_robot_cell --parallel 2
  if [[ $# -eq 0 ]]; then set -- --parts 20; fi
  "$BUILD_DIR/examples/vsd_two_robot_cell" "$@"
else
  echo "demo: the work cell needs vsd::soml, vsd::robotics, vsd::physics and vsd::collision (see the" \
       "configure messages above); running the core tour instead" >&2
  tour "$@"
fi
