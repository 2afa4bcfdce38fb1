#!/usr/bin/env python3
"""Runs train_headless over a range of seeds and reports how many episodes and wall seconds
solving took: median, worst, and how many seeds did not solve.

  scripts/seed_statistics.py [--seeds 0-9] [--config FILE] [--max-episodes N]

Finds train_headless by itself: --train-headless PATH, else where rosrun would find it when a
workspace is sourced, else the build in $CARTPOLE_WS or ~/cartpole_ws (what scripts/train.sh and test.sh
make). Standard library only.
"""
import argparse
import os
import re
import shutil
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))

RESULT = re.compile(r"^solved=(true|false) episodes=(\d+) steps=(\d+) wall_s=([0-9.]+)$")


def seed_range(text):
    first, _, last = text.partition("-")
    return range(int(first), int(last or first) + 1)


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


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=seed_range, default=seed_range("0-9"), help="e.g. 0-9 (default) or 0-99")
    parser.add_argument("--config", help="config file (default: the package's config/cartpole.yaml)")
    parser.add_argument("--max-episodes", type=int, help="override training/max_episodes")
    parser.add_argument("--train-headless", help="the train_headless executable (default: found, see above)")
    args = parser.parse_args()
    trainer = train_headless_command(args.train_headless)
    # Unless told otherwise, the config beside this script in a source tree (no package lookup
    # needed); elsewhere (an install space) train_headless's own default.
    config = args.config or os.path.join(HERE, "..", "config", "cartpole.yaml")
    config_args = ["--config", config] if os.path.isfile(config) else []

    episodes, walls, unsolved = [], [], []
    for seed in args.seeds:
        command = trainer + ["--quiet", "--seed", str(seed)] + config_args
        if args.max_episodes:
            command += ["--max-episodes", str(args.max_episodes)]
        run = subprocess.run(command, capture_output=True, text=True)
        lines = run.stdout.strip().splitlines()
        match = RESULT.match(lines[-1]) if lines else None
        if run.returncode != 0 or not match:
            sys.exit("seed %d: train_headless failed:\n%s%s" % (seed, run.stdout, run.stderr))
        print("seed %3d: %s" % (seed, lines[-1]))
        if match.group(1) == "true":
            episodes.append(int(match.group(2)))
            walls.append(float(match.group(4)))
        else:
            unsolved.append(seed)

    print("seeds %d-%d: solved %d of %d" % (args.seeds[0], args.seeds[-1], len(episodes), len(args.seeds)))
    if episodes:
        print("episodes to solve: median %g, min %d, max %d" % (statistics.median(episodes), min(episodes), max(episodes)))
        print("wall seconds to solve: median %.4f, max %.4f" % (statistics.median(walls), max(walls)))
    if unsolved:
        print("not solved: seeds %s" % ", ".join(map(str, unsolved)))
    return 1 if unsolved else 0


if __name__ == "__main__":
    sys.exit(main())
