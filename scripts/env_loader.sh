#!/usr/bin/env bash
# The env-loader of launch/train_across_hosts.launch: roslaunch runs it over SSH on each robot's
# host with the command of the node to start. Put a copy in the root of the catkin workspace on
# every host (the same path everywhere: the launch file's env_loader arg). It sources that
# workspace and says at which address the other hosts reach this one: ROS_HOSTNAME, from
# CARTPOLE_HOSTNAME in ~/.cartpole_host if that file exists, else this host's full name.
# (A ROS_IP of 127.* would make roscpp listen on 127.0.0.1 alone: use ROS_HOSTNAME.)
set -e
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
# shellcheck disable=SC1091
source "$here/devel/setup.bash"
# shellcheck disable=SC1090
[ -f "$HOME/.cartpole_host" ] && source "$HOME/.cartpole_host"
export ROS_HOSTNAME="${CARTPOLE_HOSTNAME:-$(hostname -f)}"
exec "$@"
