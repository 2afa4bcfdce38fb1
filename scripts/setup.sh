#!/usr/bin/env bash
# Sets up everything cartpole_qlearning needs and builds it (Release) in a catkin workspace.
#   - ROS already sourced (e.g. /opt/ros/noetic/setup.bash): dependencies come from rosdep.
#   - Otherwise, on Debian 11, 12 or 13: Debian's own ROS 1 packages, installed with apt-get, in
#     sets (CARTPOLE_PACKAGE_SETS below), each looked up for the release it runs on.
# The workspace: the one this clone sits in (.../ws/src/cartpole_qlearning), else
# $CARTPOLE_WS (default ~/cartpole_ws) with src/cartpole_qlearning linked to this clone.
# Source this file to get CARTPOLE_WS and the built workspace's environment in your shell,
# or run it; scripts/train.sh and scripts/test.sh run it first.
set -eo pipefail

CARTPOLE_SRC="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# catkin and rostest need the system Python with the ROS modules, not a pyenv/venv python3.
export PATH="/usr/bin:$PATH"

say() { echo "[setup] $*"; }
as_root() { if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi; }

# Debian's own ROS 1 packages (Noetic era; Debian 11, 12 and 13 have them), in sets. Which sets to
# install: CARTPOLE_PACKAGE_SETS, words of "training testing mujoco pictures sanitizers" (default:
# all of them; scripts/train.sh asks for training only, scripts/test.sh for all).
#   training    what scripts/train.sh needs: build, run and train over ROS. gtest and rostest are
#               here too: the package's CMake configure step finds them (CATKIN_ENABLE_TESTING).
#   testing     what scripts/test.sh adds: RViz (the launch file checks start nothing but need
#               every node they name), Google Benchmark, catkin_lint, the Python the tests use
#   mujoco      the MuJoCo engine (optional: found by CMake when there; Debian 12 and 13 only)
#   pictures    RViz pictures without a screen (tools/rviz_screenshot): Xvfb, Mesa, ImageMagick
#   sanitizers  tools/sanitize.sh and tools/fuzz.sh: the release's default clang (clang-N), its
#               sanitizer runtimes (libclang-rt-N-dev, or libclang-common-N-dev before clang 14)
#               and llvm-N (llvm-symbolizer), N looked up on the release it runs on
PACKAGES_training=(
  build-essential cmake pkg-config
  catkin ros-core-dev ros-message-generation python3-rostest librostest-dev libgtest-dev
  rosbash python3-roslaunch python3-rostopic python3-rosservice python3-rosnode python3-rospy
  python3-sensor-msgs python3-geometry-msgs python3-tf2-msgs python3-std-msgs python3-rosgraph-msgs
  libroscpp-dev libroslib-dev libsensor-msgs-dev libstd-msgs-dev libgeometry-msgs-dev
  libros-rosgraph-msgs-dev libtf2-ros-dev libnodeletlib-dev libnodeletlib-tools pluginlib-dev
  libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure libeigen3-dev libyaml-cpp-dev
  python3-yaml
)
PACKAGES_testing=(
  rviz libbenchmark-dev catkin-lint
  python3-numpy python3-pil python3-matplotlib python3-rosbag python3-genpy
)
PACKAGES_mujoco=(libmujoco-dev)
PACKAGES_pictures=(xvfb imagemagick libgl1-mesa-dri)
# PACKAGES_sanitizers: looked up (sanitizer_packages below).
PACKAGE_SETS=(${CARTPOLE_PACKAGE_SETS:-training testing mujoco pictures sanitizers})

# What each optional set turns on, for the one line that says it is off.
declare -A FEATURE=(
  [mujoco]="the MuJoCo engine (physics/engine: mujoco) and its tests are off"
  [pictures]="RViz pictures without a screen (tools/rviz_screenshot) are off"
  [sanitizers]="the sanitized suite and the fuzzers (tools/sanitize.sh, tools/fuzz.sh) are off"
)

release_name() {
  (. /etc/os-release 2>/dev/null && echo "${PRETTY_NAME:-this system}") || echo "this system"
}

# Whether apt knows a package (has a candidate version) on this release.
apt_knows() {
  local candidate
  candidate=$(apt-cache policy "$1" 2>/dev/null | sed -n 's/^ *Candidate: *//p')
  [ -n "$candidate" ] && [ "$candidate" != "(none)" ]
}

installed() {
  dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"
}

# The release's default clang (the version its `clang` package depends on): clang-N llvm-N and
# the sanitizer runtimes. Sets LLVM_VERSION.
sanitizer_packages() {
  LLVM_VERSION=$(apt-cache depends clang 2>/dev/null | sed -n 's/^ *Depends: clang-\([0-9][0-9]*\)$/\1/p' | head -n 1)
  [ -n "$LLVM_VERSION" ] || return 1
  PACKAGES_sanitizers=("clang-$LLVM_VERSION" "llvm-$LLVM_VERSION")
  if apt_knows "libclang-rt-$LLVM_VERSION-dev"; then
    PACKAGES_sanitizers+=("libclang-rt-$LLVM_VERSION-dev")
  else
    PACKAGES_sanitizers+=("libclang-common-$LLVM_VERSION-dev")
  fi
}

apt_lists_present() {
  compgen -G "/var/lib/apt/lists/*_Packages*" >/dev/null
}

install_dependencies() {
  if [ -n "${ROS_DISTRO:-}" ] && command -v catkin_make >/dev/null 2>&1; then
    say "ROS ${ROS_DISTRO} is sourced: installing dependencies with rosdep"
    if command -v rosdep >/dev/null 2>&1; then
      rosdep install --from-paths "$CARTPOLE_SRC" --ignore-src -y -r || say "rosdep could not install everything; the build will say what is missing"
    else
      say "rosdep is not installed; assuming the dependencies are there"
    fi
    return
  fi
  if ! command -v apt-get >/dev/null 2>&1; then
    echo "[setup] neither a sourced ROS nor apt-get: source your ROS setup.bash first" >&2
    exit 1
  fi
  # Names are looked up on this release (apt-cache), so apt needs its lists: a new machine has none.
  local updated=0
  if ! apt_lists_present; then
    say "no apt package lists yet: apt-get update"
    as_root apt-get update -qq
    updated=1
  fi
  local wanted=() set p
  for set in "${PACKAGE_SETS[@]}"; do
    case "$set" in
      training | testing | mujoco | pictures) ;;
      sanitizers)
        if ! sanitizer_packages; then
          say "$(release_name) names no default clang: ${FEATURE[sanitizers]}"
          continue
        fi
        export CARTPOLE_LLVM_VERSION="$LLVM_VERSION"
        ;;
      *)
        echo "[setup] unknown package set '$set' in CARTPOLE_PACKAGE_SETS (training testing mujoco pictures sanitizers)" >&2
        exit 1
        ;;
    esac
    local -n list="PACKAGES_$set"
    for p in "${list[@]}"; do
      if installed "$p" || [ "$set" = training ] || [ "$set" = testing ] || apt_knows "$p"; then
        wanted+=("$p")
      else
        # An optional part this release does not have: said once, and the rest goes on.
        say "$(release_name) has no $p: ${FEATURE[$set]}"
      fi
    done
    unset -n list
  done
  local missing=()
  for p in "${wanted[@]}"; do
    installed "$p" || missing+=("$p")
  done
  if [ "${#missing[@]}" -gt 0 ]; then
    say "installing ${#missing[@]} Debian packages (${PACKAGE_SETS[*]}): ${missing[*]}"
    [ "$updated" = 1 ] || as_root apt-get update -qq
    as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  else
    say "Debian packages (${PACKAGE_SETS[*]}): all present"
  fi
}

choose_workspace() {
  local parent
  parent="$(dirname "$CARTPOLE_SRC")"
  if [ "$(basename "$parent")" = "src" ] && [ -z "${CARTPOLE_WS:-}" ]; then
    CARTPOLE_WS="$(dirname "$parent")"
    say "workspace: $CARTPOLE_WS (this clone is in its src/)"
    return
  fi
  CARTPOLE_WS="${CARTPOLE_WS:-$HOME/cartpole_ws}"
  mkdir -p "$CARTPOLE_WS/src"
  local link="$CARTPOLE_WS/src/cartpole_qlearning"
  if [ -e "$link" ] && [ ! -L "$link" ]; then
    echo "[setup] $link exists and is not a link to this clone; set CARTPOLE_WS to another folder" >&2
    exit 1
  fi
  ln -sfn "$CARTPOLE_SRC" "$link"
  say "workspace: $CARTPOLE_WS (src/cartpole_qlearning -> $CARTPOLE_SRC)"
}

build() {
  cd "$CARTPOLE_WS"
  # Warnings are errors for developers and CI only (scripts/test.sh sets CARTPOLE_WARNINGS_AS_ERRORS=ON):
  # a user's compiler may warn about what ours did not, and must still build it.
  local args=(-DCMAKE_BUILD_TYPE=Release "-DCARTPOLE_WARNINGS_AS_ERRORS=${CARTPOLE_WARNINGS_AS_ERRORS:-OFF}")
  [ -x /usr/bin/python3 ] && args+=(-DPYTHON_EXECUTABLE=/usr/bin/python3)
  say "building (catkin_make, Release; about 3 minutes from scratch on 2 cores); log in $CARTPOLE_WS/build.log"
  if ! catkin_make "${args[@]}" "$@" >"$CARTPOLE_WS/build.log" 2>&1; then
    tail -n 40 "$CARTPOLE_WS/build.log" >&2
    echo "[setup] the build failed (full log: $CARTPOLE_WS/build.log)" >&2
    exit 1
  fi
  cd - >/dev/null
}

install_dependencies
choose_workspace
# Arguments are catkin_make's only when this script is run; sourced by train.sh or test.sh, the
# positional parameters are theirs (roslaunch's seed:=3, --screen) and must not reach make.
if [ "${BASH_SOURCE[0]}" = "$0" ]; then
  build "$@"
else
  build
fi
# setup.bash scripts read unset variables; relax -u style checks while sourcing.
set +e
# shellcheck disable=SC1091
source "$CARTPOLE_WS/devel/setup.bash"
export CARTPOLE_WS
say "ready: source $CARTPOLE_WS/devel/setup.bash"
