#!/usr/bin/env bash
# Installs what is missing (Debian packages), configures and builds viscompm into build/.
# Sourced by scripts/demo.sh and scripts/test.sh; safe to run again when everything is there.
# It takes no arguments; VISCOMPM_JOBS (a positive whole number) and VISCOMPM_BUILD_DIR (a
# directory it can make) are checked first: a bad one is one line on stderr naming it, exit 2.
set -euo pipefail

VISCOMPM_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${VISCOMPM_BUILD_DIR:-$VISCOMPM_ROOT/build}"
JOBS="${VISCOMPM_JOBS:-$(nproc)}"
setup_fail() { echo "setup.sh: $*" >&2; exit 2; }
# Sourced, "$@" are the caller's arguments: only a script run by itself has none to take.
if [ "${BASH_SOURCE[0]}" = "$0" ] && [ $# -gt 0 ]; then
  case "$1" in -h|--help) sed -n '2,5p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;; esac
  setup_fail "takes no arguments, got '$1'"
fi
[[ "$JOBS" =~ ^[1-9][0-9]{0,3}$ ]] || setup_fail "VISCOMPM_JOBS='$JOBS' is not a positive whole number"
mkdir -p "$BUILD_DIR" 2>/dev/null || setup_fail "VISCOMPM_BUILD_DIR: cannot make the directory $BUILD_DIR"
[ -w "$BUILD_DIR" ] || setup_fail "VISCOMPM_BUILD_DIR: cannot write to $BUILD_DIR"

packages=(
  cmake g++ make ccache
  trilinos-all-dev libptscotch-dev libscotch-dev   # Trilinos' CMake files name scotch by path
  libopenmpi-dev openmpi-bin
  libeigen3-dev libhdf5-openmpi-dev
  libassimp-dev libopenvdb-dev libtbb-dev libboost-iostreams-dev   # meshes, level sets (geometry/)
  paraview python3-paraview xvfb xauth ffmpeg                        # pictures: scripts/render.sh
  libgtest-dev
  python3 python3-numpy python3-h5py python3-matplotlib python3-pil   # tests, plots
  python3-scipy                                                      # scripts/measure_scenes.py
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "viscompm: installing ${missing[*]}"
  sudo_cmd=()
  [ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# Open MPI refuses to run as root (containers, CI) and more ranks than cores unless told.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1

# VISCOMPM_CMAKE_ARGS: extra configure options (scripts/test.sh --sanitize sets VISCOMPM_SANITIZE).
# shellcheck disable=SC2086
cmake -S "$VISCOMPM_ROOT" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release ${VISCOMPM_CMAKE_ARGS:-} >/dev/null
# VISCOMPM_BUILD_TARGET: one target instead of all (scripts/test.sh --no-trilinos sets it).
cmake --build "$BUILD_DIR" -j "$JOBS" ${VISCOMPM_BUILD_TARGET:+--target "$VISCOMPM_BUILD_TARGET"}
