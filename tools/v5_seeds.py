#!/usr/bin/env python3
"""Trains one table per seed with train_headless on a config (config/inverted_pendulum_v5.yaml by
default) and prints a Markdown table: per seed, the episodes and steps to the end of training,
whether the solved window reached the task's mark, the mean return of the last 100 episodes (the
returns the task scores: task/solved_reward, else task/reward), and the training steps at the first
greedy check of N episodes that all balanced to the step limit (--greedy-check N); then the
medians and the count of seeds solved. The figures of docs/mujoco.md come from one run of it:

  export GYMNASIUM_MUJOCO_ASSETS=.../gymnasium/envs/mujoco/assets
  python3 tools/v5_seeds.py --config config/inverted_pendulum_v5.yaml --seeds 0-9 --jobs 2

train_headless is found on PATH, else by catkin_find (source devel/setup.bash), or given with
--train-headless. Nothing is written (--no-run-folder).
"""
import argparse
import concurrent.futures
import re
import statistics
import subprocess
import sys

from robust_seeds import find_train_headless, seeds


def train(train_headless, config, seed, greedy_check):
    command = [train_headless, '--config', config, '--seed', str(seed), '--no-run-folder', '--quiet', '--returns',
               '--greedy-check', str(greedy_check)]
    out = subprocess.run(command, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit('seed %d: %s exited %d\n%s' % (seed, ' '.join(command), out.returncode, out.stderr))
    text = out.stdout
    result = re.search(r'solved=(\S+) episodes=(\d+) steps=(\d+) train_s=(\S+)', text)
    returns = [float(r) for r in re.search(r'^returns=(.*)$', text, re.M).group(1).split()]
    greedy = re.search(r'greedy_check=\d+ first_pass_steps=(\S+)', text).group(1)
    last = returns[-100:]
    return {
        'seed': seed,
        'solved': result.group(1),
        'episodes': int(result.group(2)),
        'steps': int(result.group(3)),
        'train_s': float(result.group(4)),
        'mean_100': sum(last) / len(last) if last else 0.0,
        'greedy': None if greedy == 'never' else int(greedy),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--config', default='config/inverted_pendulum_v5.yaml')
    parser.add_argument('--seeds', type=seeds, default=seeds('0-9'))
    parser.add_argument('--greedy-check', type=int, default=10, help='episodes of the greedy check (default 10)')
    parser.add_argument('--train-headless', default=find_train_headless())
    parser.add_argument('--jobs', type=int, default=1, help='seeds trained at a time (default 1)')
    args = parser.parse_args()
    if args.jobs < 1:
        parser.error('--jobs %d: at least 1' % args.jobs)
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        rows = list(pool.map(lambda s: train(args.train_headless, args.config, s, args.greedy_check), args.seeds))
    print('| seed | episodes | steps | solved | last-100 mean | %d greedy at the limit, first at step | train s |'
          % args.greedy_check)
    print('| --- | --- | --- | --- | --- | --- | --- |')
    for r in rows:
        print('| %d | %d | %d | %s | %.1f | %s | %.1f |' % (r['seed'], r['episodes'], r['steps'], r['solved'],
                                                          r['mean_100'], 'never' if r['greedy'] is None
                                                          else r['greedy'], r['train_s']))
    # A seed whose check never passed counts as later than any step.
    greedy = statistics.median(r['greedy'] if r['greedy'] is not None else float('inf') for r in rows)
    print('| median | %g | %g | %d of %d | %.1f | %s (%d of %d passed) | |' % (
        statistics.median(r['episodes'] for r in rows), statistics.median(r['steps'] for r in rows),
        sum(r['solved'] == 'true' for r in rows), len(rows), statistics.median(r['mean_100'] for r in rows),
        'never' if greedy == float('inf') else '%g' % greedy, sum(r['greedy'] is not None for r in rows), len(rows)))


if __name__ == '__main__':
    main()
