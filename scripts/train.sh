#!/usr/bin/env bash
# Sets everything up (scripts/setup.sh) and trains over ROS: roslaunch train.launch (sim and
# controller in lockstep) until solved. Arguments go to roslaunch, e.g. seed:=3 or
# stop_when_solved:=false. The table is saved to ~/.ros/cartpole_qlearning/cartpole/q_table.yaml (runs/ beside it keeps each run's checkpoints).
set -eo pipefail
# Only what training needs (scripts/setup.sh's "training" set): no test, picture or sanitizer tools.
export CARTPOLE_PACKAGE_SETS="${CARTPOLE_PACKAGE_SETS:-training}"
# shellcheck disable=SC1091
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
exec roslaunch cartpole_qlearning train.launch "$@"
