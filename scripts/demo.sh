#!/usr/bin/env bash
# Builds and runs the main vsd demo (examples/vsd_demo). Arguments are passed to the demo.
#   bash scripts/demo.sh
# Environment: BUILD_DIR (default build), VSD_SKIP_DEPS=1 to skip the dependency check.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

BUILD_DIR="${BUILD_DIR:-build}"

bash scripts/install-deps.sh
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release
cmake --build "$BUILD_DIR" --target vsd_demo --parallel 2
"$BUILD_DIR/examples/vsd_demo" "$@"
