#!/usr/bin/env bash
# How cartpole_qlearning's training scales with the number of simulated robots, in one run.
#
# For every robot count N of BENCH_ROBOTS (default 1 2 4 8), roslaunch cartpole_qlearning
# train.launch robots:=N seed:=0 is run to SOLVED, with the master already up:
#   two-process (nodelet:=false, one launch per N) and nodelet (nodelet:=true, BENCH_NODELET_RUNS
#   launches per N, median; a nodelet launch trains for 0.3 s, so its figures are noisier).
# From each launch's log:
#   - wall time to SOLVED: the wall stamp of the learner's SOLVED log line
#     ("[ INFO] [1795349059.980000000]: qlearning_controller: SOLVED after ...") minus
#     `date +%s.%N` taken just before roslaunch is started;
#   - episodes, steps (of ended episodes) and training seconds T (0.1 s resolution) of that line;
#   - steps/s two ways: steps / T, and steps / (stamp of SOLVED - stamp of the learner's first
#     line "qlearning_controller: training, seed ..."), which has ns resolution. The SOLVED
#     line's T counts from the same instant (started_, set just before that line is printed), so
#     the two agree within T's rounding; the stamp figure is the one used (for both modes).
#   Each N's step count is checked against train_headless --robots N --seed 0 (the core alone):
#   the same seed trains the same table in every loop, so the counts must agree.
#
# A profile of what bounds the two-process loop, taken in the same two-process launches (no
# extra runs): a small rospy helper, started before roslaunch and subscribed to the learner's
# /cartpole/episode_stats (decoded with the publisher's own message definition, so a stale Python
# build of EpisodeStats does not matter), finds the learner and every sim as descendants of that launch (by
# parent pid and executable name, never by a name search over the machine, where another
# user's nodes may have the same names). At an episode end, at most every 0.2 s (and at the
# SOLVED episode), it reads the message's total_steps and, at that same moment:
#   /proc/<pid>/stat utime, stime of the learner and of each sim (every thread, dead ones too),
#   /proc/<pid>/task/*/status voluntary_ctxt_switches, nonvoluntary_ctxt_switches (these are
#     per thread in Linux: summed over the threads), /proc/<pid>/task/*/stat (per thread CPU),
#   /proc/stat (the whole machine's busy time) and its own CPU time.
# The window runs from the first such sample at least 0.5 s after the first episode ended (start-
# up excluded) to the last sample in which every process was still readable (the SOLVED episode's
# when the learner had not exited yet). Figures are differences between those two samples:
# CPU us per step (user, system; learner, all sims together), context switches per step, cores
# in use (CPU seconds / window seconds), and the busiest single learner thread's CPU per step
# (a thread cannot go beyond one core: 1e6 / that is a ceiling no number of cores lifts).
# Accuracy: CPU times come in ticks of 1/CLK_TCK s (10 ms; windows are seconds long, so < 1 %);
# total_steps counts ended episodes only, so the steps of each robot's episode in progress at
# either end are missed or counted late: at most N * 500 steps at each end (a few % for 8
# robots), with no bias on average. The helper's own CPU use is measured and printed.
#
# Then a paragraph "what bounds the scaling" computed from those figures, and the targets:
#   two-process steps/s with 4 robots >= 2 x with 1 robot;
#   nodelet wall time to SOLVED with 4 robots <= with 1 robot.
#
# Nothing is pinned by default (BENCH_CPU=none): how the fleet spreads over the cores is what is
# measured. With BENCH_CPU (a taskset CPU list) the launches run on those CPUs (the profiling
# helper does not) and the core count used in the analysis is theirs.
# Another user's processes on the same machine take CPU from these runs: the profile prints the
# machine's busy cores not accounted for by the fleet ("rest") for each window.
#
# usage: bash bench/run_fleet_benchmarks.sh   (with the workspace sourced: source devel/setup.bash)
# environment: BENCH_ROBOTS  robot counts, default "1 2 4 8"
#              BENCH_NODELET_RUNS  nodelet launches per robot count, >= 1, default 3
#              BENCH_CPU  taskset CPU list for the launches, default none (not pinned)
#              BENCH_TRAIN_TIMEOUT  seconds a launch may take before it is stopped, default 120
#              BENCH_KEEP_LOGS=1  keep the temporary directory (logs, Q-tables) after a good run
# It starts its own roscore on a free port (ROS_MASTER_URI), keeps logs and Q-tables in a
# temporary ROS_HOME, and stops every process it started when it exits. About 1.5 minutes
# with the defaults on a 2-CPU machine.
set -euo pipefail

ME=run_fleet_benchmarks.sh
# shellcheck source-path=SCRIPTDIR source=bench_common.sh
source "$(dirname "${BASH_SOURCE[0]}")/bench_common.sh"
ROBOTS_LIST=${BENCH_ROBOTS:-1 2 4 8}
NODELET_RUNS=${BENCH_NODELET_RUNS:-3}
TRAIN_TIMEOUT=${BENCH_TRAIN_TIMEOUT:-120}
CPU=${BENCH_CPU:-none}
SAMPLE_PERIOD=0.2 # s, the profile's sampling period (at episode ends)
WARM=0.5          # s after the first episode end before the profile window may start
PKG=cartpole_qlearning

[[ "$ROBOTS_LIST" =~ ^[1-9][0-9]*( [1-9][0-9]*)*$ ]] ||
  die "BENCH_ROBOTS='$ROBOTS_LIST' is not allowed (whole numbers >= 1, one space apart)"
[[ "$NODELET_RUNS" =~ ^[1-9][0-9]*$ ]] || die "BENCH_NODELET_RUNS=$NODELET_RUNS is not allowed (a whole number >= 1)"
[[ "$TRAIN_TIMEOUT" =~ ^[1-9][0-9]*$ ]] || die "BENCH_TRAIN_TIMEOUT=$TRAIN_TIMEOUT is not allowed (whole seconds >= 1)"
PIN=()
if [[ "$CPU" != none ]]; then
  PIN=(taskset -c "$CPU")
  "${PIN[@]}" true 2>/dev/null || die "cannot run on CPUs $CPU (BENCH_CPU)"
fi
CORES=$("${PIN[@]}" nproc)

rospack find "$PKG" >/dev/null 2>&1 || die "package $PKG not found: source the workspace's devel/setup.bash"
TRAIN_HEADLESS=$(catkin_find --first-only --libexec "$PKG" train_headless 2>/dev/null | head -n 1)
[[ -n "$TRAIN_HEADLESS" && -x "$TRAIN_HEADLESS" ]] || die "train_headless not found: build the workspace"
/usr/bin/python3 -c "import genpy.dynamic, rospy" 2>/dev/null ||
  die "python3 cannot import rospy and genpy (the profile's helper needs them; Debian: python3-rospy)"

make_work cartpole_fleet_bench
export ROS_LOG_DIR="$ROS_HOME/log"
mkdir -p "$WORK/tmp"
RESULTS="$WORK/results.txt"
: >"$RESULTS"

# --- The profiling helper -----------------------------------------------------------------------
# usage: fleet_profile.py OUT PIDFILE ROBOTS PERIOD WARM
# OUT: one line of key=value figures (written when the learner has SOLVED, has exited, or on
# SIGINT/SIGTERM). PIDFILE: the launch's pid, written by this script once roslaunch has started.
cat >"$WORK/fleet_profile.py" <<'EOF'
import os, signal, sys, threading, time
import genpy.dynamic
import rospy

out_path, pid_file, robots, period, warm = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
TICK = os.sysconf("SC_CLK_TCK")


def read(path):
    with open(path) as f:
        return f.read()


def after_comm(stat):  # the fields of a /proc stat line after "(comm)": index 0 is field 3 (state)
    return stat[stat.rindex(")") + 2:].split()


def cpu_ticks(path):  # utime, stime
    f = after_comm(read(path))
    return int(f[11]), int(f[12])


def counters(pid):
    """utime, stime, voluntary and involuntary context switches (all threads), ticks per thread."""
    ut, st = cpu_ticks("/proc/%d/stat" % pid)
    vol = invol = 0
    threads = {}
    for tid in os.listdir("/proc/%d/task" % pid):
        try:
            tu, ts = cpu_ticks("/proc/%d/task/%s/stat" % (pid, tid))
            status = read("/proc/%d/task/%s/status" % (pid, tid))
        except OSError:
            continue
        for line in status.splitlines():
            if line.startswith("voluntary_ctxt_switches:"):
                vol += int(line.split()[1])
            elif line.startswith("nonvoluntary_ctxt_switches:"):
                invol += int(line.split()[1])
        threads[int(tid)] = tu + ts
    return ut, st, vol, invol, threads


def machine_busy():  # busy and all ticks of every CPU together
    f = [int(x) for x in read("/proc/stat").splitlines()[0].split()[1:]]
    busy = f[0] + f[1] + f[2] + f[5] + f[6] + (f[7] if len(f) > 7 else 0)
    return busy, busy + f[3] + f[4]


def discover(root):
    """The learner and the sims among root's descendants (by parent pid and executable)."""
    children = {}
    for d in os.listdir("/proc"):
        if d.isdigit():
            try:
                children.setdefault(int(after_comm(read("/proc/%s/stat" % d))[1]), []).append(int(d))
            except (OSError, ValueError, IndexError):
                pass
    learner, sims, todo = None, [], [root]
    while todo:
        for c in children.get(todo.pop(), []):
            todo.append(c)
            try:
                exe = os.path.basename(read("/proc/%d/cmdline" % c).split("\0")[0])
            except OSError:
                continue
            if exe == "qlearning_controller":
                learner = c
            elif exe == "cartpole_sim":
                sims.append(c)
    return learner, sorted(sims)


lock = threading.Lock()
samples = []
st = {"first": None, "first_wall": None, "last": -1e9, "learner": None, "sims": [], "solved": False, "messages": 0}


def pids_known():
    if st["learner"] is not None and len(st["sims"]) == robots:
        return True
    try:
        root = int(read(pid_file))
    except (OSError, ValueError):
        return False
    learner, sims = discover(root)
    if learner is not None and len(sims) == robots:
        st["learner"], st["sims"] = learner, sims
        return True
    return False


classes = {}


def on_stats(raw):
    # Decoded with the publisher's own definition (from the connection header), not with the
    # workspace's generated Python class, which can lag behind the C++ one after a change.
    now = time.monotonic()
    header = raw._connection_header
    cls = classes.get(header["md5sum"])
    if cls is None:
        cls = genpy.dynamic.generate_dynamic(header["type"], header["message_definition"])[header["type"]]
        classes[header["md5sum"]] = cls
    msg = cls().deserialize(raw._buff)
    with lock:
        st["messages"] += 1
        if st["first"] is None:
            st["first"], st["first_wall"] = now, time.time()
        if msg.solved:
            st["solved"] = True
        elif now - st["last"] < period:
            return
        if not pids_known():
            return
        try:
            procs = {p: counters(p) for p in [st["learner"]] + st["sims"]}
        except OSError:
            return  # one of them has exited
        t = os.times()
        samples.append({"t": now, "wall": time.time(), "steps": msg.total_steps, "procs": procs, "machine": machine_busy(),
                        "self": t.user + t.system})
        st["last"] = now


stop = threading.Event()
signal.signal(signal.SIGINT, lambda *_: stop.set())
signal.signal(signal.SIGTERM, lambda *_: stop.set())
rospy.init_node("fleet_profile", anonymous=True, disable_signals=True)
rospy.Subscriber("/cartpole/episode_stats", rospy.AnyMsg, on_stats, queue_size=1000, tcp_nodelay=True)
print("ready", flush=True)
while not stop.is_set():
    with lock:
        if st["solved"]:
            break
        learner = st["learner"]
    if learner is not None and not os.path.exists("/proc/%d" % learner):
        break
    time.sleep(0.05)
time.sleep(0.1)  # a SOLVED message in its callback

with lock:
    first = next((s for s in samples if st["first"] is not None and s["t"] >= st["first"] + warm), None)
    last = samples[-1] if samples else None
    if first is None or last is None or last["t"] - first["t"] < 0.5 or last["steps"] <= first["steps"]:
        line = "error=%s samples=%d messages=%d" % ("no_window" if first is None else "window_too_short", len(samples),
                                                   st["messages"])
    else:
        win = last["t"] - first["t"]
        steps = last["steps"] - first["steps"]
        fig = {"window_s": win, "steps": steps, "rate": steps / win, "samples": samples.index(last) - samples.index(first) + 1,
               "sims": len(st["sims"]), "messages": st["messages"],
               "first_msg_wall": st["first_wall"], "start_wall": first["wall"], "start_steps": first["steps"]}
        for role, pids in (("learner", [st["learner"]]), ("sims", st["sims"])):
            d = [sum(last["procs"][p][k] - first["procs"][p][k] for p in pids) for k in range(4)]
            fig[role + "_user_us"] = d[0] / TICK * 1e6 / steps
            fig[role + "_sys_us"] = d[1] / TICK * 1e6 / steps
            fig[role + "_vcsw"] = d[2] / steps
            fig[role + "_ivcsw"] = d[3] / steps
            fig[role + "_cores"] = (d[0] + d[1]) / TICK / win
            busiest = max(last["procs"][p][4][tid] - first["procs"][p][4].get(tid, 0)
                          for p in pids for tid in last["procs"][p][4])
            fig[role + "_thread_us"] = busiest / TICK * 1e6 / steps
            fig[role + "_thread_cores"] = busiest / TICK / win
        busy = last["machine"][0] - first["machine"][0]
        fig["machine_cores"] = busy / TICK / win
        fig["profiler_cores"] = (last["self"] - first["self"]) / win
        line = " ".join("%s=%.17g" % kv for kv in fig.items())
with open(out_path + ".tmp", "w") as f:
    f.write(line + "\n")
os.rename(out_path + ".tmp", out_path)
sys.stdout.flush()
os._exit(0)
EOF

# --- The master ---------------------------------------------------------------------------------
start_master
# rosout up too: the launches' log lines go through it
for _ in $(seq 100); do
  rosnode list 2>/dev/null | grep -qx /rosout && break
  sleep 0.1
done

N_COUNT=$(wc -w <<<"$ROBOTS_LIST")
echo "Measuring (about $((N_COUNT * 12 + N_COUNT * NODELET_RUNS * 2 + 5)) s): master $ROS_MASTER_URI, logs in $WORK" >&2

# Runs train.launch to its end: sets T0 (just before roslaunch) and T_END. With a pid file, the
# launch's pid is written there for the profiling helper.
launch()
{
  local log=$1 pidfile=$2 pid rc=0
  shift 2
  T0=$(date +%s.%N)
  start "$log" "${PIN[@]}" timeout -s INT -k 5 "$TRAIN_TIMEOUT" roslaunch "$PKG" train.launch "$@"
  pid=$STARTED
  if [[ -n "$pidfile" ]]; then
    echo "$pid" >"$pidfile.tmp"
    mv "$pidfile.tmp" "$pidfile"
  fi
  wait "$pid" || rc=$?
  T_END=$(date +%s.%N)
  forget "$pid"
  ((rc == 0)) || die "roslaunch $PKG train.launch $* exited with $rc (log: $WORK/$log)"
}

# "stamp_of_training stamp_of_SOLVED episodes steps T" from a launch log.
solved_figures()
{
  local log=$WORK/$1 train solved
  train=$({ grep -aoE '\[[0-9]+\.[0-9]+\]: qlearning_controller: training, seed [0-9]+' "$log" || true; } | head -n 1)
  solved=$({ grep -aoE '\[[0-9]+\.[0-9]+\]: qlearning_controller: SOLVED after [0-9]+ episodes, [0-9]+ steps, [0-9.]+ s' "$log" ||
    true; } | tail -n 1)
  [[ -n "$solved" ]] || die "no SOLVED line with a wall stamp (log: $log)"
  [[ -n "$train" ]] || die "no 'qlearning_controller: training, seed' line with a wall stamp (log: $log)"
  awk -v a="$train" -v b="$solved" 'BEGIN { split(a, x, /[][]/); split(b, y, /[][ ]+/); print x[2], y[2], y[7], y[9], y[11] }'
}

# --- Two-process launches, profiled -------------------------------------------------------------
for n in $ROBOTS_LIST; do
  echo "two-process: roslaunch $PKG train.launch robots:=$n seed:=0, to SOLVED, profiled" >&2
  out="$WORK/profile_$n.txt" pidfile="$WORK/launch_$n.pid"
  start "profile_$n.log" env TMPDIR="$WORK/tmp" /usr/bin/python3 "$WORK/fleet_profile.py" "$out" "$pidfile" "$n" "$SAMPLE_PERIOD" "$WARM"
  helper=$STARTED
  for _ in $(seq 300); do
    grep -q '^ready' "$WORK/profile_$n.log" && break
    alive "$helper" || die "the profiling helper ended early (log: $WORK/profile_$n.log)"
    sleep 0.05
  done
  grep -q '^ready' "$WORK/profile_$n.log" || die "the profiling helper did not start (log: $WORK/profile_$n.log)"
  launch "process_$n.log" "$pidfile" robots:="$n" nodelet:=false seed:=0
  for _ in $(seq 50); do
    [[ -f "$out" ]] && break
    sleep 0.1
  done
  [[ -f "$out" ]] || stop "$helper" # it writes its figures on SIGINT
  wait "$helper" 2>/dev/null || true
  forget "$helper"
  [[ -f "$out" ]] || die "the profiling helper wrote no figures (log: $WORK/profile_$n.log)"
  figures=$(solved_figures "process_$n.log") || exit 1
  read -r ts_train ts_solved episodes steps train_s <<<"$figures"
  echo "kind=process robots=$n t0=$T0 t_end=$T_END ts_train=$ts_train ts_solved=$ts_solved episodes=$episodes steps=$steps T=$train_s" \
    >>"$RESULTS"
  echo "kind=profile robots=$n $(cat "$out")" >>"$RESULTS"
done

# --- Nodelet launches ---------------------------------------------------------------------------
# Round-robin over the robot counts, so that a slow patch of the machine hits every count alike.
for ((i = 1; i <= NODELET_RUNS; i++)); do
  for n in $ROBOTS_LIST; do
    echo "nodelet: roslaunch $PKG train.launch robots:=$n nodelet:=true seed:=0, to SOLVED (run $i of $NODELET_RUNS)" >&2
    launch "nodelet_${n}_$i.log" "" robots:="$n" nodelet:=true seed:=0
    figures=$(solved_figures "nodelet_${n}_$i.log") || exit 1
    read -r ts_train ts_solved episodes steps train_s <<<"$figures"
    echo "kind=nodelet robots=$n run=$i t0=$T0 t_end=$T_END ts_train=$ts_train ts_solved=$ts_solved episodes=$episodes steps=$steps T=$train_s" \
      >>"$RESULTS"
  done
done

# --- The core alone: the step counts every loop must reproduce ----------------------------------
for n in $ROBOTS_LIST; do
  "$TRAIN_HEADLESS" --robots "$n" --seed 0 --quiet --no-run-folder >"$WORK/headless_$n.log" 2>&1 ||
    die "train_headless --robots $n failed (log: $WORK/headless_$n.log)"
  echo "kind=headless robots=$n $(tail -n 1 "$WORK/headless_$n.log")" >>"$RESULTS"
done

# --- The report ---------------------------------------------------------------------------------
CPU_MODEL=$(grep -m 1 '^model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//')
echo
echo "machine: ${CPU_MODEL:-unknown CPU}, nproc $(nproc), $(uname -sr), ROS ${ROS_DISTRO:-$(rosversion -d 2>/dev/null || echo unknown)}"
echo "date:    $(date -u '+%Y-%m-%d %H:%M:%S UTC')"
if ((${#PIN[@]} > 0)); then
  echo "placement: the launches pinned to CPUs $CPU (BENCH_CPU, $CORES CPUs); the profiling helper not pinned"
else
  echo "placement: nothing pinned (BENCH_CPU=none, the default): scaling over the cores is the point, so the"
  echo "           scheduler places every process; figures vary with where it puts them"
fi
/usr/bin/python3 - "$RESULTS" "$CORES" "$NODELET_RUNS" <<'EOF'
import statistics, sys, textwrap


def say(text, first="  ", rest="    "):
    print(textwrap.fill(text, 118, initial_indent=first, subsequent_indent=rest))


def table(head, rows):
    """A markdown table: the first column left-aligned, the others right-aligned."""
    widths = [max([len(head[i])] + [len(r[i]) for r in rows]) for i in range(len(head))]
    line = lambda cells: "| " + " | ".join(c.ljust(w) if i == 0 else c.rjust(w)
                                           for i, (c, w) in enumerate(zip(cells, widths))) + " |"
    print(line(head))
    print("|" + "|".join("-" * (w + 2) for w in widths) + "|")
    for r in rows:
        print(line(r))


results, cores, nodelet_runs = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
rows = []
for line in open(results):
    rows.append(dict(kv.split("=", 1) for kv in line.split()))


def num(r, k):
    return float(r[k])


def pick(kind, n):
    return [r for r in rows if r["kind"] == kind and int(r["robots"]) == n]


counts = []
for r in rows:
    if r["kind"] == "process" and int(r["robots"]) not in counts:
        counts.append(int(r["robots"]))

print()
print("time to SOLVED, seed 0, master up (roslaunch cartpole_qlearning train.launch robots:=N nodelet:=...):")
rate, wall = {}, {}
out = []
warnings = []
for mode in ("process", "nodelet"):
    for n in counts:
        runs = pick(mode, n)
        ws = [num(r, "ts_solved") - num(r, "t0") for r in runs]
        ups = [num(r, "ts_train") - num(r, "t0") for r in runs]
        trains = [num(r, "ts_solved") - num(r, "ts_train") for r in runs]
        rs = [num(r, "steps") / t for r, t in zip(runs, trains)]
        rts = [num(r, "steps") / num(r, "T") if num(r, "T") > 0 else float("inf") for r in runs]
        med = statistics.median
        rate[(mode, n)], wall[(mode, n)] = med(rs), med(ws)
        spread = "(%.3f to %.3f)" % (min(ws), max(ws)) if len(runs) > 1 else ""
        out.append(["two-process" if mode == "process" else "nodelet", str(n), runs[0]["episodes"], runs[0]["steps"],
                    "%.3f" % med(ws) + (" " + spread if spread else ""), "%.3f" % med(ups), "%.3f" % med(trains),
                    "%.1f" % med([num(r, "T") for r in runs]), "%.0f" % med(rts), "%.0f" % med(rs)])
table(["mode", "robots", "episodes", "steps", "roslaunch to SOLVED s", "= to 'training'", "+ training", "T s (log)",
       "steps/T", "steps/s by stamps"], out)
print("  nodelet: %s; two-process: one launch each. 'training' is"
      % ("medians of %d launches (roslaunch to SOLVED: min to max)" % nodelet_runs if nodelet_runs > 1 else "one launch each"))
print("  the learner's 'training, seed' line (set up, about to wait for states); steps/s by stamps = steps / training,")
print("  the figure used below (T of the log has 0.1 s resolution)")

for n in counts:
    h = pick("headless", n)
    got = {"two-process": pick("process", n)[0]["steps"]}
    got.update({"nodelet run %s" % r["run"]: r["steps"] for r in pick("nodelet", n)})
    if not h or any(v != h[0].get("steps") for v in got.values()):
        warnings.append("robots %d: steps differ from train_headless --robots %d --seed 0 (%s): %s"
                        % (n, n, h[0].get("steps") if h else "no result", ", ".join("%s %s" % kv for kv in got.items())))

prof = {}
for n in counts:
    p = pick("profile", n)[0]
    if "error" in p:
        warnings.append("robots %d: no profile (%s: %s samples of %s episode_stats messages)"
                        % (n, p["error"], p["samples"], p["messages"]))
    else:
        prof[n] = {k: float(v) for k, v in p.items() if k not in ("kind",)}

print()
print("profile of the two-process launches (window: 0.5 s after the first episode end to SOLVED, sampled every 0.2 s):")
out = []
for n, f in prof.items():
    c = f["learner_user_us"] + f["learner_sys_us"] + f["sims_user_us"] + f["sims_sys_us"]
    f["C"] = c
    f["sys_share"] = (f["learner_sys_us"] + f["sims_sys_us"]) / c
    out.append([str(n), "%.2f" % f["window_s"], "%.0f" % f["rate"], "%.1f + %.1f" % (f["learner_user_us"], f["learner_sys_us"]),
                "%.1f + %.1f" % (f["sims_user_us"], f["sims_sys_us"]), "%.1f (%.0f %%)" % (c, 100 * f["sys_share"]),
                "%.2f + %.2f" % (f["learner_vcsw"], f["learner_ivcsw"]), "%.2f + %.2f" % (f["sims_vcsw"], f["sims_ivcsw"])])
table(["robots", "window s", "steps/s", "CPU us/step: learner usr+sys", "sims usr+sys", "total (sys %)",
       "ctx sw/step: learner vol+invol", "sims vol+invol"], out)
out = []
for n, f in prof.items():
    fleet = f["learner_cores"] + f["sims_cores"]
    f["fleet_cores"] = fleet
    rest = max(0.0, f["machine_cores"] - fleet - f["profiler_cores"])
    f["rest_cores"] = rest
    out.append([str(n), "%.2f" % f["learner_cores"], "%.2f" % f["sims_cores"], "%.2f" % fleet,
                "%.2f of %d" % (f["machine_cores"], cores), "%.2f" % rest, "%.3f" % f["profiler_cores"],
                "%.1f us/step, %.2f cores" % (f["learner_thread_us"], f["learner_thread_cores"])])
table(["robots", "cores: learner", "sims", "fleet", "machine busy", "rest of machine", "profiler",
       "busiest learner thread"], out)
print("  cores = CPU seconds / window seconds; rest = busy cores of the machine outside the fleet and the profiler")
print("  (roslaunch, rosout, and anything else running on this machine at the time)")
for n, f in prof.items():
    p = pick("process", n)[0]
    ts_train = num(p, "ts_train")
    head = f["start_wall"] - ts_train
    say("%d robot%s: the first episode ended %.2f s after the 'training' line; the %.2f s before the window ran %.0f"
        " steps/s, the window %.0f, the whole run %.0f" % (n, "" if n == 1 else "s", f["first_msg_wall"] - ts_train, head,
                                                        f["start_steps"] / head, f["rate"], rate[("process", n)]))

print()
print("what bounds the scaling (computed from the figures above; %d cores here; steady-state figures of the windows):"
      % cores)
for n, f in prof.items():
    c = f["C"]
    cpu_bound = cores * 1e6 / c
    busy = f["machine_cores"] / cores
    if busy >= 0.9:
        kind = ("CPU-bound: the machine was %.0f %% busy (%.2f of %d cores; the fleet %.2f, the rest %.2f)"
                % (100 * busy, f["machine_cores"], cores, f["fleet_cores"], f["rest_cores"]))
    elif f["learner_thread_cores"] >= 0.9:
        kind = "bound by the learner's busiest thread (%.2f of a core)" % f["learner_thread_cores"]
    elif n == 1:
        kind = ("latency-bound: one state/command round trip at a time, %.2f of %d cores busy; a step takes %.0f us"
                " of wall time and %.0f us of CPU, so the round trip is mostly CPU work in series (the kernel's"
                " loopback TCP, wake-ups), not idle waiting" % (f["machine_cores"], cores, 1e6 / f["rate"], c))
    else:
        kind = ("latency-bound: %.2f of %d cores busy; a lockstep round waits for the slowest of %d round trips while"
                " %d processes take turns on %d cores (involuntary switches per step %.2f)"
                % (f["machine_cores"], cores, n, n + 1, cores, f["learner_ivcsw"] + f["sims_ivcsw"]))
    say("%d robot%s: %s. C = %.1f us CPU/step (%.0f %% kernel), %.1f context switches/step: %d cores carry at most"
        " %d x 1e6 / C = %.0f steps/s; measured %.0f (%.0f %% of it). The learner's busiest thread: %.1f us/step, a"
        " ceiling of %.0f steps/s on any number of cores."
        % (n, "" if n == 1 else "s", kind, c, 100 * f["sys_share"],
           f["learner_vcsw"] + f["learner_ivcsw"] + f["sims_vcsw"] + f["sims_ivcsw"], cores, cores, cpu_bound, f["rate"],
           100 * f["rate"] / cpu_bound, f["learner_thread_us"], 1e6 / f["learner_thread_us"]))
base = prof.get(1)
if base and len(prof) > 1:
    text = ("Adding robots: steps/s x%s (ideal: x N), while the CPU per step goes from %.1f us (1 robot) to %s: a"
            " robot's step costs the same messages, system calls and wake-ups however many robots share the learner;"
            " more robots only overlap the round trips, and pay more involuntary switches once they outnumber the cores."
            % (", x".join("%.2f with %d" % (f["rate"] / base["rate"], n) for n, f in prof.items() if n > 1), base["C"],
               ", ".join("%.1f (%d)" % (f["C"], n) for n, f in prof.items() if n > 1)))
    saturated = [n for n, f in prof.items() if f["machine_cores"] >= 0.9 * cores]
    if saturated:
        text += (" From %d robots on the cores are saturated: throughput is held near %d x 1e6 / C whatever N; only"
                 " more cores or less CPU per step (%.0f %% of it in the kernel) lift it."
                 % (min(saturated), cores, 100 * prof[min(saturated)]["sys_share"]))
    else:
        text += (" No window saturated the cores (at most %.2f of %d busy): the lockstep rounds' latency holds the fleet"
                 " back, with the CPU bound close behind." % (max(f["machine_cores"] for f in prof.values()), cores))
    say(text)
if base is None:
    say("Predictions: no 1-robot profile (BENCH_ROBOTS lacks 1), so no per-robot latency bound.")
else:
    rate1 = base["rate"]
    for k in (cores, 16):
        say("On %d cores%s, N robots reach about min(N x rate_1, %d x 1e6 / C_N, 1e6 / learner thread us per step),"
            " rate_1 = %.0f steps/s, C_N and the thread figure as measured here%s:"
            % (k, " (this machine)" if k == cores else "", k, rate1,
               " (an upper bound: a lockstep round waits for its slowest robot)" if k == cores else ""))
        for n, f in prof.items():
            terms = [n * rate1, k * 1e6 / f["C"], 1e6 / f["learner_thread_us"]]
            i = terms.index(min(terms))
            extra = "; measured %.0f, %.0f %% of it" % (f["rate"], 100 * f["rate"] / terms[i]) if k == cores else ""
            print("    %2d robot%s: min(%.0f, %.0f, %.0f) = %.0f steps/s (bound: %s%s)"
                  % (n, " " if n == 1 else "s", terms[0], terms[1], terms[2], terms[i],
                     ("latency", "CPU", "learner thread")[i], extra))
    say("Caveat: C was measured on %d cores; on 16, more wake-ups cross CPUs (about 2x the cost of a round trip on one"
        " CPU, per run_benchmarks.sh) while fewer processes wait for a core: C may move either way." % cores)

print()
print("targets (figures of this run):")
if ("process", 1) in rate and ("process", 4) in rate:
    a, b = rate[("process", 4)], rate[("process", 1)]
    v = a / b
    if v >= 2:
        verdict = "MET, %.0f %% above" % (100 * (v / 2 - 1))
    else:
        verdict = "MISSED by %.2fx (%.0f %% short: %.0f steps/s, %.0f needed)" % (2 - v, 100 * (1 - v / 2), a, 2 * b)
    print("  two-process steps/s, 4 robots / 1 robot:      %5.2fx  (target >= 2x): %s" % (v, verdict))
else:
    print("  two-process steps/s, 4 robots / 1 robot:      not measured (BENCH_ROBOTS lacks 1 or 4)")
if ("nodelet", 1) in wall and ("nodelet", 4) in wall:
    a, b = wall[("nodelet", 4)], wall[("nodelet", 1)]
    if a <= b:
        verdict = "MET, %.3f s (%.0f %%) less" % (b - a, 100 * (1 - a / b))
    else:
        verdict = "MISSED by %.3f s (%.0f %% over)" % (a - b, 100 * (a / b - 1))
    print("  nodelet roslaunch-to-SOLVED, 4 robots vs 1:   %.3f s vs %.3f s (target <=): %s" % (a, b, verdict))
else:
    print("  nodelet roslaunch-to-SOLVED, 4 robots vs 1:   not measured (BENCH_ROBOTS lacks 1 or 4)")
for w in warnings:
    print()
    print("warning: " + w)
EOF
OK=true
