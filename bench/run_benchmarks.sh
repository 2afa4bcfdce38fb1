#!/usr/bin/env bash
# The lockstep rate of cartpole_qlearning against a bare publish-answer pair, in one run.
#
# The machine is noisy, so no figure means much alone: each is printed with its ratio to a bare
# pair of processes that exchange the same messages (a sensor_msgs/JointState shaped like the
# sim's, answered by one std_msgs/Float64), measured in the same run on the same master.
#   (a) bare_ping <-> bare_pong: round trips/s, the reference (1.00)
#   (b) cartpole_sim in lockstep (config/cartpole.yaml + config/sim.yaml, as launch/sim.launch
#       loads them; /use_sim_time true) answered by lockstep_answer, TF off and TF on: steps/s
#   (c) roslaunch cartpole_qlearning train.launch seed:=0, to solved: steps/s of the whole run
#   (d) train_headless --seed 0 --quiet (the core alone, no messages): steps/s, median of 5 runs
# (a) and (b) are measured in rounds (a, b TF off, b TF on), some before (c) and one after it;
# each figure is the median over the rounds, its spread is printed beside it. Each pair has its
# own /clock (remapped), so that no process receives another pair's clock.
# Every measured process runs on one CPU (taskset): a round trip costs about twice as much when
# the two processes sit on different CPUs (a cross-CPU wake-up), and where the scheduler puts
# them changes from run to run; pinned, (a), (b) and (c) are all measured the same way.
#
# usage: bash bench/run_benchmarks.sh   (with the workspace sourced: source devel/setup.bash)
# environment: BENCH_ROUNDS  rounds of (a) and (b), >= 2, default 3
#              BENCH_DURATION  seconds each measurement of a round counts, default 1.5
#              BENCH_CPU  the CPU every measured process runs on, default 0; "none": not pinned
#              BENCH_TRAIN_TIMEOUT  seconds (c) may take before it is stopped, default 180
#              BENCH_KEEP_LOGS=1  keep the temporary directory (logs, Q-table) after a good run
# It starts its own roscore on a free port (ROS_MASTER_URI), keeps logs and Q-tables in a
# temporary ROS_HOME, and stops every process it started when it exits.
set -euo pipefail

ROUNDS=${BENCH_ROUNDS:-3}
DURATION=${BENCH_DURATION:-1.5}
WARMUP=0.3
if ! [[ "$ROUNDS" =~ ^[0-9]+$ ]] || ((ROUNDS < 2)); then
  echo "run_benchmarks.sh: BENCH_ROUNDS=$ROUNDS is not allowed (must be a whole number >= 2)" >&2
  exit 1
fi
TRAIN_TIMEOUT=${BENCH_TRAIN_TIMEOUT:-180}
PKG=cartpole_qlearning
CPU=${BENCH_CPU-0}
PIN=()
if [[ -n "$CPU" && "$CPU" != none ]]; then
  PIN=(taskset -c "$CPU")
  "${PIN[@]}" true 2>/dev/null || { echo "run_benchmarks.sh: cannot run on CPU $CPU (BENCH_CPU)" >&2; exit 1; }
fi

die()
{
  echo "run_benchmarks.sh: $*" >&2
  exit 1
}

PKG_DIR=$(rospack find "$PKG" 2>/dev/null) || die "package $PKG not found: source the workspace's devel/setup.bash"
find_exe()
{
  local path
  path=$(catkin_find --first-only --libexec "$PKG" "$1" 2>/dev/null | head -n 1)
  [[ -n "$path" && -x "$path" ]] || die "$1 not found: build the workspace (the bench/ programs need libbenchmark-dev)"
  echo "$path"
}
BARE_PING=$(find_exe bare_ping)
BARE_PONG=$(find_exe bare_pong)
LOCKSTEP_ANSWER=$(find_exe lockstep_answer)
CARTPOLE_SIM=$(find_exe cartpole_sim)
TRAIN_HEADLESS=$(find_exe train_headless)

WORK=$(mktemp -d "${TMPDIR:-/tmp}/cartpole_bench.XXXXXX")
export ROS_HOME="$WORK/ros_home"
mkdir -p "$ROS_HOME"

# Every background process starts in a process group of its own (setsid), so that stopping it
# also stops what it started (roscore's rosmaster and rosout, roslaunch's nodes).
PIDS=()
OK=false
cleanup()
{
  local i
  for ((i = ${#PIDS[@]} - 1; i >= 0; i--)); do
    stop "${PIDS[i]}"
  done
  if $OK && [[ "${BENCH_KEEP_LOGS:-0}" != 1 ]]; then
    rm -rf "$WORK"
  elif $OK; then
    echo "run_benchmarks.sh: logs kept in $WORK" >&2
  else
    echo "run_benchmarks.sh: did not finish; logs kept in $WORK" >&2
  fi
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

# Starts a command in the background, in its own process group; its pid is in STARTED.
start()
{
  local log=$1
  shift
  setsid "$@" >"$WORK/$log" 2>&1 </dev/null &
  STARTED=$!
  PIDS+=("$STARTED")
}

# Stops one started process group and waits for it.
stop()
{
  local pid=$1
  kill -INT -- "-$pid" 2>/dev/null || true
  for _ in $(seq 50); do
    kill -0 -- "-$pid" 2>/dev/null || break
    sleep 0.1
  done
  kill -KILL -- "-$pid" 2>/dev/null || true
  wait "$pid" 2>/dev/null || true
}

# Runs a command to its end (at most timeout_s), in its own process group, output in a log.
run()
{
  local log=$1 timeout_s=$2
  shift 2
  start "$log" timeout -s INT -k 5 "$timeout_s" "$@"
  local rc=0
  wait "$STARTED" || rc=$?
  ((rc == 0)) || die "$* exited with $rc (log: $WORK/$log)"
}

# The value of key=VALUE in the last line of a log that has it.
field()
{
  { grep -o "$2=[^ ]*" "$WORK/$1" || true; } | tail -n 1 | cut -d= -f2
}

# --- The master ---------------------------------------------------------------------------------
PORT=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
export ROS_MASTER_URI="http://127.0.0.1:$PORT"
start roscore.log roscore -p "$PORT"
for _ in $(seq 150); do
  (exec 3<>"/dev/tcp/127.0.0.1/$PORT") 2>/dev/null && break
  sleep 0.1
done
(exec 3<>"/dev/tcp/127.0.0.1/$PORT") 2>/dev/null || die "roscore did not start on port $PORT (log: $WORK/roscore.log)"

echo "Measuring (about $((ROUNDS * 8 + 15)) s): master $ROS_MASTER_URI, logs in $WORK" >&2

# --- Setup of (a) and (b): the answering side stays up for the whole run --------------------
# As launch/sim.launch sets a sim up: sim time on, the shared parameters in the namespace,
# sim.yaml in the node's private namespace, then mode (and here publish_tf) over it.
rosparam set /use_sim_time true
for tf in false true; do
  ns=bench_tf_$tf
  rosparam load "$PKG_DIR/config/cartpole.yaml" "/$ns"
  rosparam load "$PKG_DIR/config/sim.yaml" "/$ns/cartpole_sim"
  start "sim_tf_$tf.log" "${PIN[@]}" "$CARTPOLE_SIM" "__ns:=$ns" "/clock:=/$ns/clock" _mode:=lockstep _seed:=0 "_publish_tf:=$tf"
done
start pong.log "${PIN[@]}" "$BARE_PONG" /clock:=/bench_bare/clock

# One round: (a), then (b) with TF off and on. Each client measures, prints its line and exits;
# a sim left unanswered waits, and publishes its state again for the next client.
measure_round()
{
  local r=$1 tf
  echo "round $r: (a) bare pair, (b) sim TF off, (b) sim TF on; ${DURATION} s each" >&2
  run "ping_$r.log" 30 "${PIN[@]}" "$BARE_PING" /clock:=/bench_bare/clock "_duration:=$DURATION" "_warmup:=$WARMUP"
  [[ -n "$(field "ping_$r.log" rate)" ]] || die "no result from bare_ping (log: $WORK/ping_$r.log)"
  for tf in false true; do
    run "answer_tf_${tf}_$r.log" 30 "${PIN[@]}" "$LOCKSTEP_ANSWER" "__ns:=bench_tf_$tf" "/clock:=/bench_tf_$tf/clock" \
      "_duration:=$DURATION" "_warmup:=$WARMUP"
    [[ -n "$(field "answer_tf_${tf}_$r.log" rate)" ]] || die "no result from lockstep_answer (log: $WORK/answer_tf_${tf}_$r.log)"
  done
}

# "median min max" of the key's values in the logs.
spread()
{
  local key=$1 log
  shift
  for log in "$@"; do field "$log" "$key"; done | sort -g | awk '{ v[NR] = $1 }
    END { m = NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2; printf "%.1f %.1f %.1f", m, v[1], v[NR] }'
}

for ((r = 1; r < ROUNDS; r++)); do
  measure_round "$r"
done

# --- (c) Training over ROS --------------------------------------------------------------------
echo "(c) roslaunch $PKG train.launch seed:=0, to solved" >&2
run train.log "$TRAIN_TIMEOUT" "${PIN[@]}" roslaunch "$PKG" train.launch seed:=0
SOLVED_LINE=$(grep -o 'SOLVED after [0-9]* episodes, [0-9]* steps, [0-9.]* s' "$WORK/train.log" | tail -n 1) ||
  die "train.launch did not print SOLVED (log: $WORK/train.log)"
read -r TRAIN_EPISODES TRAIN_STEPS TRAIN_S <<<"$(echo "$SOLVED_LINE" | awk '{ print $3, $5, $7 }')"
TRAIN_RATE=$(awk -v m="$TRAIN_STEPS" -v t="$TRAIN_S" 'BEGIN { printf "%.1f", (t > 0 ? m / t : 0) }')

measure_round "$ROUNDS"

# --- (d) The core alone -----------------------------------------------------------------------
# A run takes milliseconds and wall_s has millisecond resolution: the median of five runs.
echo "(d) train_headless --seed 0 --quiet, 5 runs" >&2
HEADLESS_RATES=()
for i in 1 2 3 4 5; do
  run "headless_$i.log" 60 "${PIN[@]}" "$TRAIN_HEADLESS" --seed 0 --quiet
  [[ "$(field "headless_$i.log" solved)" == true ]] || die "train_headless did not solve (log: $WORK/headless_$i.log)"
  HEADLESS_RATES+=("$(awk -v m="$(field "headless_$i.log" steps)" -v t="$(field "headless_$i.log" wall_s)" \
    'BEGIN { printf "%.1f", (t > 0 ? m / t : 0) }')")
done
HEADLESS_RATE=$(printf '%s\n' "${HEADLESS_RATES[@]}" | sort -g | sed -n 3p)
HEADLESS_EPISODES=$(field headless_1.log episodes)
HEADLESS_STEPS=$(field headless_1.log steps)
HEADLESS_S=$(awk -v m="$HEADLESS_STEPS" -v r="$HEADLESS_RATE" 'BEGIN { printf "%.4f", (r > 0 ? m / r : 0) }')

PING_LOGS=() OFF_LOGS=() ON_LOGS=()
for ((r = 1; r <= ROUNDS; r++)); do
  PING_LOGS+=("ping_$r.log")
  OFF_LOGS+=("answer_tf_false_$r.log")
  ON_LOGS+=("answer_tf_true_$r.log")
done
read -r BARE_RATE BARE_MIN BARE_MAX <<<"$(spread rate "${PING_LOGS[@]}")"
read -r SIM_RATE SIM_MIN SIM_MAX <<<"$(spread rate "${OFF_LOGS[@]}")"
read -r SIM_TF_RATE SIM_TF_MIN SIM_TF_MAX <<<"$(spread rate "${ON_LOGS[@]}")"
SIM_REPEATS=0
for log in "${OFF_LOGS[@]}" "${ON_LOGS[@]}"; do
  SIM_REPEATS=$((SIM_REPEATS + $(field "$log" repeats)))
done

# --- The table --------------------------------------------------------------------------------
CPU_MODEL=$(grep -m 1 '^model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//')
echo
echo "machine: $(nproc) CPUs, ${CPU_MODEL:-unknown CPU}, $(uname -sr), ROS ${ROS_DISTRO:-unknown}"
echo "date:    $(date -u '+%Y-%m-%d %H:%M UTC'); (a), (b): median of $ROUNDS rounds of ${DURATION} s (after ${WARMUP} s of warm-up)"
if ((${#PIN[@]} > 0)); then
  echo "placement: every measured process on CPU $CPU (taskset)"
else
  echo "placement: not pinned (BENCH_CPU=none): the figures depend on where the scheduler puts each process"
fi
echo
row()
{
  awk -v name="$1" -v rate="$2" -v ref="$BARE_RATE" -v note="$3" \
    'BEGIN { printf "| %-44s | %10.0f | %8.2f | %6.2f | %s\n", name, rate, 1e6 / rate, rate / ref, note }'
}
range()
{
  awk -v lo="$1" -v hi="$2" 'BEGIN { printf "rounds %.0f to %.0f", lo, hi }'
}
printf "| %-44s | %10s | %8s | %6s | %s\n" "measurement" "per second" "us each" "x bare" "notes"
printf "|%s|%s|%s|%s|%s\n" "$(printf -- '-%.0s' $(seq 46))" "$(printf -- '-%.0s' $(seq 12))" \
  "$(printf -- '-%.0s' $(seq 10))" "$(printf -- '-%.0s' $(seq 8))" "------"
row "(a) bare pair, JointState -> Float64: trips" "$BARE_RATE" "reference; $(range "$BARE_MIN" "$BARE_MAX")"
row "(b) cartpole_sim lockstep, TF off: steps" "$SIM_RATE" "$(range "$SIM_MIN" "$SIM_MAX")"
row "(b) cartpole_sim lockstep, TF on: steps" "$SIM_TF_RATE" "$(range "$SIM_TF_MIN" "$SIM_TF_MAX")"
row "(c) train.launch seed:=0: steps" "$TRAIN_RATE" \
  "$TRAIN_STEPS steps, $TRAIN_EPISODES episodes, ${TRAIN_S} s to SOLVED"
row "(d) train_headless --seed 0: steps" "$HEADLESS_RATE" \
  "the core alone; $HEADLESS_STEPS steps, $HEADLESS_EPISODES episodes, ${HEADLESS_S} s (median of 5)"
if ((SIM_REPEATS > 0)); then
  echo
  echo "warning: a sim published $SIM_REPEATS state(s) again in (b): an answer took longer than lockstep_timeout"
fi
OK=true
