#!/usr/bin/env bash
# Sets everything up (scripts/setup.sh) and trains: arguments go to train_headless
# (e.g. --seed 3 --save q_table.yaml).
set -eo pipefail
# shellcheck disable=SC1091
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
exec rosrun cartpole_qlearning train_headless "$@"
