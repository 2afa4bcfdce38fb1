#!/usr/bin/env python3
"""Runs train_headless over a range of seeds and reports how fast it learns: how many seeds
solved, the median, 90th percentile and worst episodes to solve, the median steps and the
median wall time to solve.

  scripts/seed_statistics.py [--seeds 0-9] [--config FILE] [--max-episodes N] [-j N]
  scripts/seed_statistics.py --table [--seeds 0-99] [--max-episodes N] [-j N] [--anchor FILE]

--table runs every shipped config (config/cartpole.yaml, config/tiles.yaml when it exists,
config/tutorial.yaml) and, for reference, the tutorial's method in Python with Gymnasium
(<repo>/../shared/anchors/gym_tabular_q.py, beside the development tree; skipped with a note
where it is absent, as in a user's clone) over the same seeds, and prints one markdown table
with the machine and the date: the "How fast it learns" table of docs/results.md.

Statistics over all the seeds run: a seed that did not solve within --max-episodes ranks
after every solved one, so a percentile that falls on it reads "> N". Steps and wall time are
the medians over the solved seeds. Wall time is the training loop's own (train_headless's
train_s, the saved table's verdict apart; the anchor's wall_s), not process start-up. With -j 2 two runs share the CPUs and
the wall times are noisier; -j 1 (the default) times one run at a time.

Finds train_headless by itself: --train-headless PATH, else where rosrun would find it when a
workspace is sourced, else the build in $CARTPOLE_WS or ~/cartpole_ws (what scripts/train.sh and test.sh
make). Standard library only.
"""
import argparse
import concurrent.futures
import datetime
import os
import platform
import re
import shutil
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.realpath(os.path.join(HERE, ".."))
CONFIG_DIR = os.path.join(REPO, "config")
DEFAULT_ANCHOR = os.path.join(os.path.dirname(REPO), "shared", "anchors", "gym_tabular_q.py")
ANCHOR_PYTHON = "/usr/bin/python3"  # Debian's, where python3-numpy is installed

RETURNS = re.compile(r"^returns=([-0-9.e ]*)$", re.MULTILINE)
RESULT = re.compile(r"^until=\w+ reached=(?:true|false) solved=(true|false|n/a) episodes=(\d+) steps=(\d+) "
                    r"train_s=([0-9.]+) verdict_s=[0-9.]+$")
ANCHOR_RESULT = re.compile(r"^(solved|unsolved) seed=\d+ episodes=(\d+) steps=(\d+) wall_s=([0-9.]+)")

# The shipped configs of the table, in its order: (file in config/, what the row is called).
# CartPole-v1's solved criterion, which every shipped config keeps: a mean return of at least
# SOLVED_RETURN over the last WINDOW episodes, each returning at most FULL_RETURN (500 steps).
WINDOW, SOLVED_RETURN, FULL_RETURN = 100, 475, 500

SHIPPED = [("cartpole.yaml", "default, bins"), ("tiles.yaml", "tile coding"), ("tutorial.yaml", "the tutorial's settings")]


class Run:
    def __init__(self, seed, solved, episodes, steps, wall_s, line):
        self.seed, self.solved, self.episodes, self.steps, self.wall_s, self.line = (seed, solved, episodes, steps,
                                                                                      wall_s, line)
        self.returns = None  # every episode's return, when asked for (train_headless --returns)


class Summary:
    """What the runs of one config over the seeds add up to."""

    def __init__(self, runs, max_episodes):
        self.runs = runs
        self.max_episodes = max_episodes
        self.solved = [r for r in runs if r.solved]
        self.unsolved = [r.seed for r in runs if not r.solved]

    def ranked(self):
        """Episodes to solve, fewest first, then None for each unsolved seed."""
        return sorted(r.episodes for r in self.solved) + [None] * len(self.unsolved)

    def text(self, value):
        return "> %d" % self.max_episodes if value is None else "%g" % value

    def median_text(self):
        ranked = self.ranked()
        middle = ranked[(len(ranked) - 1) // 2:len(ranked) // 2 + 1]  # one value, or the two middle ones
        return self.text(None if None in middle else sum(middle) / len(middle))

    def percentile_90_text(self):
        ranked = self.ranked()
        return self.text(ranked[-(-len(ranked) * 9 // 10) - 1])  # nearest rank: ceil(0.9 n), counted from 1

    def worst_text(self):
        return self.text(self.ranked()[-1])

    def median_steps(self):
        return statistics.median(r.steps for r in self.solved) if self.solved else None

    def median_wall_s(self):
        return statistics.median(r.wall_s for r in self.solved) if self.solved else None


def seed_range(text):
    """'0-99', '1,17,19' or both ('0-4,9'): the seeds in the order given."""
    seeds = []
    try:
        for part in text.split(","):
            first, _, last = part.strip().partition("-")
            seeds.extend(range(int(first), int(last or first) + 1))
    except ValueError:
        raise argparse.ArgumentTypeError("%s is not a list of seeds such as 0-99 or 1,17,19" % text)
    if not seeds:
        raise argparse.ArgumentTypeError("%s is an empty range" % text)
    return seeds


def train_headless_command(explicit):
    """The command that runs train_headless, or exits saying where it looked."""
    if explicit:
        return [explicit]
    if os.environ.get("ROS_PACKAGE_PATH") and shutil.which("catkin_find"):
        # Found once, as rosrun would find it (rosrun itself costs about 0.4 s a call).
        found = subprocess.run(["catkin_find", "--first-only", "--libexec", "cartpole_qlearning", "train_headless"],
                               capture_output=True, text=True)
        path = found.stdout.strip()
        if found.returncode == 0 and os.access(path, os.X_OK):
            return [path]
    looked = []
    for workspace in (os.environ.get("CARTPOLE_WS"), os.path.expanduser("~/cartpole_ws")):
        if workspace:
            candidate = os.path.join(workspace, "devel", "lib", "cartpole_qlearning", "train_headless")
            looked.append(candidate)
            if os.access(candidate, os.X_OK):
                return [candidate]
    sys.exit("train_headless not found: source your workspace's devel/setup.bash, or pass --train-headless PATH "
             "(looked with catkin_find and in %s)" % ", ".join(looked))


def run_seeds(seeds, jobs, command_for, parse, label):
    """Runs command_for(seed) for every seed, jobs at a time; returns the Runs in seed order."""

    def one(seed):
        command = command_for(seed)
        done = subprocess.run(command, capture_output=True, text=True)
        lines = done.stdout.strip().splitlines()
        run = parse(seed, lines[-1]) if lines else None
        returns = RETURNS.search(done.stdout)
        if run is not None and returns:
            run.returns = [float(value) for value in returns.group(1).split()]
        if run is None:
            sys.exit("%s, seed %d: %s failed (exit %d):\n%s%s" % (label, seed, " ".join(command), done.returncode,
                                                                    done.stdout, done.stderr))
        return run

    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        return list(pool.map(one, seeds))


def parse_train_headless(seed, line):
    match = RESULT.match(line)
    if not match:
        return None
    return Run(seed, match.group(1) == "true", int(match.group(2)), int(match.group(3)), float(match.group(4)), line)


def parse_anchor(seed, line):
    match = ANCHOR_RESULT.match(line)
    if not match:
        return None
    return Run(seed, match.group(1) == "solved", int(match.group(2)), int(match.group(3)), float(match.group(4)), line)


def train_headless_runs(trainer, config, seeds, max_episodes, jobs, returns=False):
    config_args = ["--config", config] if config else []
    episodes_args = ["--max-episodes", str(max_episodes)] if max_episodes else []
    returns_args = ["--returns"] if returns else []
    return run_seeds(seeds, jobs,
                     lambda seed: trainer + ["--quiet", "--no-run-folder", "--seed", str(seed)] + config_args
                     + episodes_args + returns_args,
                     parse_train_headless, config or "train_headless")


def where_episodes_go(runs, window, full_return):
    """Medians over the solved runs: the first episode that returned full_return, the episodes short
    of it from there to solved, and the short episodes and the missing return in the solved window."""
    first, short_after, short_in_window, missing = [], [], [], []
    for run in runs:
        if not run.solved or not run.returns:
            continue
        full = [i for i, value in enumerate(run.returns) if value >= full_return]
        if not full:
            continue
        first.append(full[0] + 1)
        short_after.append(sum(1 for value in run.returns[full[0]:] if value < full_return))
        last = run.returns[-window:]
        short_in_window.append(sum(1 for value in last if value < full_return))
        missing.append(sum(full_return - value for value in last))
    if not first:
        return None
    return [statistics.median(values) for values in (first, short_after, short_in_window, missing)]


def config_max_episodes(config):
    """training/max_episodes of a config file (a plain scan: the standard library has no YAML)."""
    in_training = False
    with open(config) as text:
        for line in text:
            if re.match(r"^\S", line):
                in_training = line.startswith("training:")
            match = re.match(r"^\s+max_episodes:\s*(\d+)", line)
            if in_training and match:
                return int(match.group(1))
    return 1000  # train_headless's default


def describe_seeds(seeds):
    """'0-9' for a run of consecutive seeds, else the list ('1,17,19')."""
    if len(seeds) > 1 and list(seeds) == list(range(seeds[0], seeds[0] + len(seeds))):
        return "%d-%d" % (seeds[0], seeds[-1])
    return ",".join(str(seed) for seed in seeds)


def print_summary(summary, seeds, timing_note):
    print("seeds %s: solved %d of %d" % (describe_seeds(seeds), len(summary.solved), len(summary.runs)))
    if summary.solved:
        print("episodes to solve: median %s, 90th percentile %s, worst %s, best %d" %
              (summary.median_text(), summary.percentile_90_text(), summary.worst_text(),
               min(r.episodes for r in summary.solved)))
        print("steps to solve: median %g" % summary.median_steps())
        print("wall seconds to solve: median %.4f, max %.4f%s" %
              (summary.median_wall_s(), max(r.wall_s for r in summary.solved), timing_note))
    if summary.unsolved:
        print("not solved within %d episodes: seeds %s" % (summary.max_episodes, ", ".join(map(str, summary.unsolved))))


def cpu_model():
    try:
        with open("/proc/cpuinfo") as info:
            for line in info:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def load_average():
    """The 1-minute load average: above the CPU count, other processes were competing for the CPUs."""
    try:
        with open("/proc/loadavg") as load:
            return load.read().split()[0]
    except OSError:
        return "unknown"


def table_row(name, summary, count):
    steps, wall = summary.median_steps(), summary.median_wall_s()
    return "| %s | %d of %d | %s | %s | %s | %s | %s |" % (
        name, len(summary.solved), count, summary.median_text(), summary.percentile_90_text(), summary.worst_text(),
        "%d" % steps if steps is not None else "-",
        "%.2f" % (wall * 1000.0) if wall is not None else "-")


def table(args, trainer):
    max_episodes = args.max_episodes or 2000
    load_before = load_average()
    rows, analysis, notes = [], [], []
    for file_name, name in SHIPPED:
        config = os.path.join(CONFIG_DIR, file_name)
        if not os.path.isfile(config):
            if file_name != "tiles.yaml":
                sys.exit("%s is missing: --table needs the package's source tree" % config)
            continue
        print("%s: seeds %s ..." % (file_name, describe_seeds(args.seeds)), file=sys.stderr, flush=True)
        summary = Summary(train_headless_runs(trainer, config, args.seeds, max_episodes, args.jobs), max_episodes)
        label = "`%s` (%s)" % (file_name, name)
        rows.append(table_row(label, summary, len(args.seeds)))
        # Once more with every episode's return (the same seeds give the same episodes), apart
        # from the timed runs above.
        medians = where_episodes_go(train_headless_runs(trainer, config, args.seeds, max_episodes, args.jobs, True),
                                    WINDOW, FULL_RETURN)
        if medians:
            analysis.append("| %s | %g | %g | %g | %g |" % tuple([label] + medians))

    anchor = args.anchor
    name = "Python anchor `gym_tabular_q.py` (the tutorial's method with Gymnasium and numpy)"
    if not os.path.isfile(anchor):
        notes.append("The Python anchor was skipped: %s is not there (it sits beside the development tree, "
                     "not in a clone)." % anchor)
    elif subprocess.run([ANCHOR_PYTHON, "-c", "import numpy"], capture_output=True).returncode != 0:
        notes.append("The Python anchor was skipped: %s cannot import numpy (Debian: python3-numpy)." % ANCHOR_PYTHON)
    else:
        print("anchor: seeds %s (minutes) ..." % describe_seeds(args.seeds), file=sys.stderr, flush=True)
        runs = run_seeds(args.seeds, args.jobs, lambda seed: [ANCHOR_PYTHON, anchor, str(seed), str(max_episodes)],
                         parse_anchor, "anchor")
        rows.append(table_row(name, Summary(runs, max_episodes), len(args.seeds)))

    print("Seeds %s, at most %d episodes each; %s, %d CPUs, load average %s before and %s after; %s." %
          (describe_seeds(args.seeds), max_episodes, cpu_model(), os.cpu_count(), load_before, load_average(),
           datetime.date.today().isoformat()))
    print()
    print("| config | seeds solved | median episodes to solve | 90th percentile | worst | median steps to solve "
          "| median wall ms to solve |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for row in rows:
        print(row)
    print()
    if analysis:
        print("Where the episodes go (medians over the solved seeds; a window of %d episodes solves when it misses "
              "at most %d of the %d steps it can hold):" % (WINDOW, WINDOW * (FULL_RETURN - SOLVED_RETURN),
                                                            WINDOW * FULL_RETURN))
        print()
        print("| config | first episode returning %d | episodes short of %d after it, to solved "
              "| short episodes in the solved window | return missing from the solved window |" % (FULL_RETURN,
                                                                                                  FULL_RETURN))
        print("| --- | --- | --- | --- | --- |")
        for row in analysis:
            print(row)
        print()
    if args.jobs > 1:
        notes.append("Runs went %d at a time (-j %d): they shared the CPUs, so the wall times are noisier than "
                     "one at a time." % (args.jobs, args.jobs))
    notes.append("Wall time is the training loop's, to solved (not process start-up); steps and wall time are "
                 "medians over the solved seeds.")
    for note in notes:
        print(note)
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=seed_range, help="e.g. 0-9 (default; 0-99 with --table)")
    parser.add_argument("--config", help="config file (default: the package's config/cartpole.yaml)")
    parser.add_argument("--max-episodes", type=int, help="override training/max_episodes (--table: 2000 for every row)")
    parser.add_argument("-j", "--jobs", type=int, default=1, help="runs at a time (default 1: undisturbed wall times)")
    parser.add_argument("--table", action="store_true", help="every shipped config and the Python anchor, as a "
                        "markdown table")
    parser.add_argument("--anchor", default=DEFAULT_ANCHOR, help="the Python anchor (default: %(default)s)")
    parser.add_argument("--train-headless", help="the train_headless executable (default: found, see above)")
    args = parser.parse_args()
    if args.jobs < 1:
        parser.error("-j %d is not allowed (at least 1)" % args.jobs)
    if args.max_episodes is not None and args.max_episodes < 1:
        parser.error("--max-episodes %d is not allowed (at least 1)" % args.max_episodes)
    if args.seeds is None:
        args.seeds = seed_range("0-99" if args.table else "0-9")
    if args.table and args.config:
        parser.error("--table runs the shipped configs; --config is for one config")
    trainer = train_headless_command(args.train_headless)
    if args.table:
        return table(args, trainer)

    # Unless told otherwise, the config beside this script in a source tree (no package lookup
    # needed); elsewhere (an install space) train_headless's own default.
    config = args.config or os.path.join(CONFIG_DIR, "cartpole.yaml")
    if not os.path.isfile(config):
        if args.config:
            sys.exit("%s: no such file" % config)
        config = None
    max_episodes = args.max_episodes or (config_max_episodes(config) if config else 1000)
    runs = train_headless_runs(trainer, config, args.seeds, args.max_episodes, args.jobs)
    for run in runs:
        print("seed %3d: %s" % (run.seed, run.line))
    summary = Summary(runs, max_episodes)
    print_summary(summary, args.seeds, " (-j %d: runs shared the CPUs)" % args.jobs if args.jobs > 1 else "")
    return 1 if summary.unsolved else 0


if __name__ == "__main__":
    sys.exit(main())
