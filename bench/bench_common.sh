# shellcheck shell=bash
# The process and master helpers that the bench/ scripts share, sourced by each:
# source "$(dirname "${BASH_SOURCE[0]}")/bench_common.sh"
# Defines functions only. The sourcing script sets ME (its name, the prefix of its messages) and
# calls make_work before it starts anything; make_work sets WORK, PIDS and OK, and cleanup reads
# them on the way out (the script sets OK=true once it has printed everything).

die()
{
  echo "$ME: $*" >&2
  exit 1
}

# Every background process starts in a process group of its own (setsid), so that stopping it
# also stops what it started (roscore's rosmaster and rosout). roslaunch starts each node in a
# session of its own, so on the way out the descendants of a started process are stopped by pid
# too, should roslaunch not have stopped them.

# The pids of every descendant of a process.
descendants()
{
  ps -eo pid=,ppid= | awk -v root="$1" '{ parent[$1] = $2 }
    END { n = 1; q[1] = root; for (i = 1; i <= n; i++) for (p in parent) if (parent[p] == q[i]) { q[++n] = p; print p } }'
}

# True while a process exists and is not a zombie.
alive()
{
  local state
  state=$(ps -o stat= -p "$1" 2>/dev/null) || return 1
  [[ "$state" != Z* ]]
}

# Stops one started process group (and every descendant of its leader) and waits for it.
stop()
{
  local pid=$1 d others
  others=$(descendants "$pid")
  kill -INT -- "-$pid" 2>/dev/null || true
  for _ in $(seq 50); do
    alive "$pid" || break
    sleep 0.1
  done
  kill -KILL -- "-$pid" 2>/dev/null || true
  for d in $others; do
    alive "$d" && kill -KILL "$d" 2>/dev/null
  done
  wait "$pid" 2>/dev/null || true
}

# Drops a pid that has been waited for from the ones to stop on the way out (its number may be
# reused by then, and stop would signal that process's descendants).
forget()
{
  local i
  for i in "${!PIDS[@]}"; do
    [[ "${PIDS[i]}" == "$1" ]] && unset 'PIDS[i]'
  done
  PIDS=("${PIDS[@]}")
}

# On the way out: stops every started process that is still in PIDS, newest first, and removes
# WORK after a good run (OK=true) unless BENCH_KEEP_LOGS=1.
cleanup()
{
  local i
  for ((i = ${#PIDS[@]} - 1; i >= 0; i--)); do
    stop "${PIDS[i]}"
  done
  if $OK && [[ "${BENCH_KEEP_LOGS:-0}" != 1 ]]; then
    rm -rf "$WORK"
  elif $OK; then
    echo "$ME: logs kept in $WORK" >&2
  else
    echo "$ME: did not finish; logs kept in $WORK" >&2
  fi
}

# Makes the temporary directory WORK ($TMPDIR/<prefix>.XXXXXX) with the run's ROS_HOME in it
# (logs, Q-tables), and from then on runs cleanup on the way out.
make_work()
{
  WORK=$(mktemp -d "${TMPDIR:-/tmp}/$1.XXXXXX")
  export ROS_HOME="$WORK/ros_home"
  mkdir -p "$ROS_HOME"
  PIDS=()
  OK=false
  trap cleanup EXIT
  trap 'exit 130' INT
  trap 'exit 143' TERM
}

# Starts a command in the background, in its own process group; its pid is in STARTED.
start()
{
  local log=$1
  shift
  setsid "$@" >"$WORK/$log" 2>&1 </dev/null &
  STARTED=$!
  PIDS+=("$STARTED")
}

# Starts a roscore of this run's own on a free port (ROS_MASTER_URI) and waits until the master
# accepts connections.
start_master()
{
  local port
  port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
  export ROS_MASTER_URI="http://127.0.0.1:$port"
  start roscore.log roscore -p "$port"
  for _ in $(seq 150); do
    (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null && break
    sleep 0.1
  done
  (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null || die "roscore did not start on port $port (log: $WORK/roscore.log)"
}

# The executable NAME of package $PKG (catkin_find), or the run ends saying how to get it.
find_exe()
{
  local path
  path=$(catkin_find --first-only --libexec "$PKG" "$1" 2>/dev/null | head -n 1)
  [[ -n "$path" && -x "$path" ]] || die "$1 not found: build the workspace (the bench/ programs need libbenchmark-dev)"
  echo "$path"
}

# Sets PIN to the prefix that runs a command on CPU $1 (taskset -c), or to nothing for "none" or
# "", and ends the run when that CPU cannot be used.
pin_to_cpu()
{
  PIN=()
  if [[ -n "$1" && "$1" != none ]]; then
    PIN=(taskset -c "$1")
    "${PIN[@]}" true 2>/dev/null || die "cannot run on CPU $1 (BENCH_CPU)"
  fi
}
