#!/usr/bin/env bash
# Installs the Debian packages of the groups named on the command line, and says what it installs.
# Idempotent: when every package is already installed, apt is not touched at all. Uses sudo only when
# not running as root.
#
#   bash scripts/install-deps.sh GROUP...     e.g. `core scene physics`; `all` is every group
#
# Groups:
#   core        the toolchain, CMake and Eigen: all vsd::core (and vsd::io, vsd::soml, vsd::robotics) need
#   analysis    vsd::analysis: pugixml (the PNML reader's XML parser)
#   scene       vsd::scene: urdfdom (URDF) and assimp (meshes); vsd::robotics needs nothing more
#   dist        vsd::dist: Cyclone DDS (C API) and its IDL compiler idlc
#   collision   vsd::collision: FCL 0.7 and libccd
#   physics     vsd::physics: ODE 0.16 (through pkg-config)
#   web         vsd::web: cpp-httplib; npm (the page's JavaScript libraries come from the npm registry,
#               pinned by src/web/page/package-lock.json) unless an npm is installed already
#   modules     all of the six above
#   python      the Python bindings (the extension module vsd, VSD_WITH_PYTHON): pybind11 and the Python
#               headers to build it, NumPy (arrays of vectors, frames and columns), pytest (its tests) and
#               matplotlib (the example's plot)
#   tests       GoogleTest and GoogleMock; Orocos KDL (the robotics tests' reference), gnuplot (the
#               examples' plots), python3 (the docs' C++ blocks are compiled by a test), ccache (the
#               packaging tests' builds reuse the Release tree's objects), Chromium (the inspector's
#               page is tested in headless Chromium; playwright-core comes from npm)
#   benchmarks  Google Benchmark and the peers the benchmarks compare with: RTTR, Qt 5, Boost.Signals2,
#               libsigc++ 3, Lua 5.4, LuaJIT 2.1, MuJoCo 2.2, DART 6 (its URDF loader and ODE collision detector)
#   fuzzing     clang and libFuzzer's runtime
# A module whose packages are missing is skipped at configure time with a message, not the build; on a
# system without apt, install the same libraries with its package manager (README.md lists them per
# module) and set VSD_SKIP_DEPS=1.
#
# Set VSD_SKIP_DEPS=1 to skip this step (e.g. on a machine whose dependencies are managed otherwise).
set -euo pipefail

declare -A GROUP
GROUP[core]="build-essential cmake g++ libeigen3-dev"
GROUP[analysis]="libpugixml-dev"
GROUP[scene]="liburdfdom-dev libassimp-dev"
GROUP[dist]="cyclonedds-dev cyclonedds-tools"
GROUP[collision]="libfcl-dev libccd-dev"
GROUP[physics]="libode-dev pkg-config"
GROUP[web]="libcpp-httplib-dev pkg-config @npm"
GROUP[python]="pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib"
GROUP[tests]="libgtest-dev libgmock-dev liborocos-kdl-dev gnuplot-nox python3 ccache chromium"
GROUP[benchmarks]="libbenchmark-dev librttr-dev qtbase5-dev libboost-dev libsigc++-3.0-dev liblua5.4-dev libluajit-5.1-dev libmujoco-dev libdart-dev libdart-utils-urdf-dev libdart-collision-ode-dev"
GROUP[fuzzing]="clang libclang-rt-14-dev"
MODULES="analysis scene dist collision physics web"
ALL="core $MODULES python tests benchmarks fuzzing"

if [[ "${VSD_SKIP_DEPS:-0}" == "1" ]]; then
  echo "install-deps: VSD_SKIP_DEPS=1, skipping"
  exit 0
fi
if [[ $# -eq 0 ]]; then
  echo "usage: install-deps.sh GROUP... (core analysis scene dist collision physics web modules python tests benchmarks fuzzing all)" >&2
  exit 2
fi

groups=()
for g in "$@"; do
  case "$g" in
    all) read -r -a more <<<"$ALL"; groups+=("${more[@]}") ;;
    modules) read -r -a more <<<"$MODULES"; groups+=("${more[@]}") ;;
    *)
      if [[ -z "${GROUP[$g]+x}" ]]; then
        echo "install-deps: unknown group '$g'" >&2
        exit 2
      fi
      groups+=("$g")
      ;;
  esac
done

packages=()
for g in "${groups[@]}"; do
  read -r -a more <<<"${GROUP[$g]}"
  packages+=("${more[@]}")
done
# "@npm": Debian's nodejs and npm, unless some npm is on the PATH already (NodeSource's nodejs carries its
# own npm and conflicts with Debian's npm package).
resolved=()
for pkg in "${packages[@]}"; do
  if [[ "$pkg" == "@npm" ]]; then
    if ! command -v npm >/dev/null 2>&1; then resolved+=(nodejs npm); fi
  else
    resolved+=("$pkg")
  fi
done
packages=("${resolved[@]}")
mapfile -t packages < <(printf '%s\n' "${packages[@]}" | awk '!seen[$0]++')

missing=()
for pkg in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q '^install ok installed$'; then
    missing+=("$pkg")
  fi
done

echo "install-deps: groups ${groups[*]}: ${#packages[@]} packages (${packages[*]})"
if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install-deps: all already installed"
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
