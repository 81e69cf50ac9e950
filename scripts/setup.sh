# Shared by scripts/play and scripts/test: install what is missing, configure, build.
# Sourced, not run. Honours DRAPE_BUILD_DIR (default: build) and DRAPE_CMAKE_ARGS.

set -euo pipefail

DRAPE_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
DRAPE_BUILD_DIR=${DRAPE_BUILD_DIR:-"$DRAPE_ROOT/build"}

# Debian packages: what building and playing needs (scripts/play), and what the tests and
# benchmarks add (scripts/test).
DRAPE_PLAY_PACKAGES=(
  build-essential cmake
  libeigen3-dev libassimp-dev libtbb-dev nlohmann-json3-dev libcli11-dev libstb-dev
  libegl-dev libgl-dev libopengl-dev libegl-mesa0 libgl1-mesa-dri libx11-dev
  ffmpeg
)
DRAPE_TEST_PACKAGES=(
  "${DRAPE_PLAY_PACKAGES[@]}"
  pkg-config git libgles-dev
  libgtest-dev libgmock-dev googletest libbenchmark-dev libbullet-dev
  gnuplot-nox xvfb xauth
)

drape_log() { printf 'drape: %s\n' "$*" >&2; }

# Installs the packages that are missing; reinstalls nothing.
drape_install_packages() {
  local missing=()
  local pkg
  for pkg in "$@"; do
    if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
      missing+=("$pkg")
    fi
  done
  if [ ${#missing[@]} -eq 0 ]; then
    return 0
  fi
  drape_log "installing missing Debian packages: ${missing[*]}"
  local sudo=()
  if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null 2>&1; then
      sudo=(sudo)
    else
      drape_log "error: not root and no sudo; install these packages first: ${missing[*]}"
      return 1
    fi
  fi
  export DEBIAN_FRONTEND=noninteractive
  "${sudo[@]}" apt-get update -qq
  "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
}

# Runs a command and prints how long it took: `drape_timed WHAT command...`.
drape_timed() {
  local what=$1 start rc=0
  shift
  start=$(date +%s)
  "$@" || rc=$?
  drape_log "$what: $(( $(date +%s) - start )) s"
  return "$rc"
}

# True when the build folder's cache holds every -DNAME=VALUE of the arguments.
drape_cache_has() {
  local cache="$DRAPE_BUILD_DIR/CMakeCache.txt" arg name value
  [ -f "$cache" ] || return 1
  for arg in "$@"; do
    [[ "$arg" =~ ^-D([A-Za-z_0-9]+)=(.*)$ ]] || continue
    name=${BASH_REMATCH[1]}
    value=${BASH_REMATCH[2]}
    grep -q "^${name}:[A-Z]*=${value}\$" "$cache" || return 1
  done
}

# drape_build [--target TARGET] [-DNAME=VALUE...]: configures (Release) when there is no
# build yet, when DRAPE_CMAKE_ARGS is set or when the cache differs from the -D values
# asked for, then builds incrementally in $DRAPE_BUILD_DIR: TARGET only, or everything.
# With ccache installed it is the compiler launcher, its base directory the checkout, so
# that a clone in another folder is served from the same cache. ccache takes -march=native
# as written, not as the CPU it means: the compiler's target options for this CPU are its
# compiler check, so that another CPU does not get this one's objects.
drape_build() {
  local target=() args=()
  while [ $# -gt 0 ]; do
    if [ "$1" = "--target" ]; then
      target=(--target "$2")
      shift 2
    else
      args+=("$1")
      shift
    fi
  done
  local extra=(${DRAPE_CMAKE_ARGS:-})
  if command -v ccache >/dev/null 2>&1; then
    export CCACHE_BASEDIR="$DRAPE_ROOT"
    export CCACHE_COMPILERCHECK="%compiler% -march=native -Q --help=target"
    args+=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  fi
  if [ ${#extra[@]} -gt 0 ] || ! drape_cache_has "${args[@]}"; then
    cmake -S "$DRAPE_ROOT" -B "$DRAPE_BUILD_DIR" -DCMAKE_BUILD_TYPE=Release "${args[@]}" "${extra[@]}" >/dev/null
  fi
  drape_timed "build ($DRAPE_BUILD_DIR)" cmake --build "$DRAPE_BUILD_DIR" --parallel "$(nproc)" "${target[@]}"
}
