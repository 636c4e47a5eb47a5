#!/usr/bin/env bash
# Builds everything and runs the whole vsd test suite with ctest.
#   bash scripts/test.sh [extra cmake configure arguments...]
# It installs the core, every module's libraries, the Python bindings' packages and the tests' packages
# (scripts/install-deps.sh core modules python tests), and the benchmarks' too when the arguments switch them on (-DVSD_BUILD_BENCHMARKS=ON).
# Environment:
#   BUILD_DIR        build directory (default build)
#   BUILD_TYPE       CMAKE_BUILD_TYPE (default Release, the same tree scripts/demo.sh uses)
#   VSD_WERROR       ON to build vsd's own targets with -Werror (default OFF)
#   CTEST_ARGS       extra arguments for ctest, e.g. "-L cmake" or "-LE cmake"
#   VSD_SKIP_DEPS=1  skip the dependency check
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

BUILD_DIR="${BUILD_DIR:-build}"
BUILD_TYPE="${BUILD_TYPE:-Release}"
VSD_WERROR="${VSD_WERROR:-OFF}"

groups=(core modules python tests)
for arg in "$@"; do
  [[ "$arg" == "-DVSD_BUILD_BENCHMARKS=ON" ]] && groups+=(benchmarks)
done
bash scripts/install-deps.sh "${groups[@]}"
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE="$BUILD_TYPE" -DVSD_WERROR="$VSD_WERROR" -DVSD_BUILD_TESTS=ON "$@"
cmake --build "$BUILD_DIR" --parallel 2
# shellcheck disable=SC2086  # CTEST_ARGS is split on purpose
ctest --test-dir "$BUILD_DIR" --output-on-failure -j2 --no-tests=error ${CTEST_ARGS:-}
