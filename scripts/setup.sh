#!/usr/bin/env bash
# Sets up everything cartpole_qlearning needs and builds it (Release) in a catkin workspace.
#   - ROS already sourced (e.g. /opt/ros/noetic/setup.bash): dependencies come from rosdep.
#   - Otherwise, on Debian 12: Debian's own ROS 1 packages, installed with apt-get.
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

# Debian 12's ROS 1 packages (Noetic era) that build, run and test the package.
DEBIAN_PACKAGES=(
  build-essential cmake pkg-config
  catkin ros-core-dev ros-message-generation python3-rostest librostest-dev
  rosbash python3-roslaunch python3-rostopic python3-rosservice python3-rosnode
  python3-sensor-msgs python3-geometry-msgs python3-tf2-msgs python3-std-msgs python3-rosgraph-msgs
  libroscpp-dev libroslib-dev libsensor-msgs-dev libstd-msgs-dev libgeometry-msgs-dev
  libros-rosgraph-msgs-dev libtf2-ros-dev libnodeletlib-dev libnodeletlib-tools pluginlib-dev
  libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure libeigen3-dev libyaml-cpp-dev
  libgtest-dev libbenchmark-dev catkin-lint rviz
  python3-rospy xvfb imagemagick libgl1-mesa-dri python3-numpy python3-pil python3-yaml
  clang-14 libclang-rt-14-dev llvm-14
  python3-matplotlib python3-numpy python3-rosbag python3-rospy python3-genpy
  libmujoco-dev
)

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
  local missing=()
  for p in "${DEBIAN_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ "${#missing[@]}" -gt 0 ]; then
    say "installing ${#missing[@]} Debian packages: ${missing[*]}"
    as_root apt-get update -qq
    as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  else
    say "Debian packages: all present"
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
  local args=(-DCMAKE_BUILD_TYPE=Release)
  [ -x /usr/bin/python3 ] && args+=(-DPYTHON_EXECUTABLE=/usr/bin/python3)
  say "building (catkin_make, Release; about 1 to 3 minutes from scratch on 2 cores); log in $CARTPOLE_WS/build.log"
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
