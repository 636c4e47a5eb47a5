#!/usr/bin/env bash
# Installs the Debian packages vsd needs to build, test and benchmark. Idempotent: when every package
# is already installed, apt is not touched at all. Uses sudo only when not running as root.
#
# Set VSD_SKIP_DEPS=1 to skip this step (e.g. on a machine whose dependencies are managed otherwise).
set -euo pipefail

# The one list of packages.
PACKAGES=(
  # toolchain and core dependencies
  build-essential
  cmake
  g++
  libeigen3-dev
  # compiler cache: the packaging tests' builds of vsd reuse the objects of .ci/run's Release tree
  ccache
  # vsd::analysis: the PNML reader's XML parser (the module is skipped without it)
  libpugixml-dev
  # vsd::scene: URDF and mesh loading
  liburdfdom-dev
  libassimp-dev
  # vsd::dist: Cyclone DDS (C API) and its IDL compiler idlc
  cyclonedds-dev
  cyclonedds-tools
  # vsd::collision: FCL 0.7 (narrow and broad phase) and libccd (its GJK/EPA for convex pairs)
  libfcl-dev
  libccd-dev
  # vsd::robotics: Orocos KDL, the independent library its tests and benchmarks compare against (not a
  # dependency of the module itself)
  liborocos-kdl-dev
  # vsd::physics: rigid-body dynamics (ODE 0.16, double precision)
  libode-dev
  # examples/physics/falling_objects draws its PNG with gnuplot (skipped with a message without it)
  gnuplot-nox
  # tests and benchmarks
  libgtest-dev
  libgmock-dev
  libbenchmark-dev
  # peers the benchmarks compare against
  librttr-dev
  qtbase5-dev
  libboost-dev
  libsigc++-3.0-dev
  # the SOML++ VM benchmarks run the same functions in Lua 5.4, embedded (skipped without it)
  liblua5.4-dev
  # fuzzing (libFuzzer comes with clang's runtime)
  clang
  libclang-rt-14-dev
)

if [[ "${VSD_SKIP_DEPS:-0}" == "1" ]]; then
  echo "install-deps: VSD_SKIP_DEPS=1, skipping"
  exit 0
fi

missing=()
for pkg in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q '^install ok installed$'; then
    missing+=("$pkg")
  fi
done

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install-deps: all ${#PACKAGES[@]} packages already installed"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
if [[ "$(id -u)" -eq 0 ]]; then
  SUDO=()
elif command -v sudo >/dev/null 2>&1; then
  SUDO=(sudo)
else
  echo "install-deps: not root and sudo is not available; please install: ${missing[*]}" >&2
  exit 1
fi

"${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update
"${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${missing[@]}"
