#!/usr/bin/env python3
"""Trains one table per seed with train_headless and a config that runs the robustness suite
(e.g. config/robust.yaml), and prints a Markdown table: per seed, the episodes and steps to the
table it saved, the run's training seconds (train_s of its result line: the saved table's final
verdict apart) and the CPU seconds of its whole process, and the suite's per-case counts; then the median and worst seed
of each column. The figures of docs/robust_tables.md come from one run of it:

  python3 tools/robust_seeds.py --config config/robust.yaml --seeds 0-19   (or --seeds 1,17,19)

--jobs N runs N seeds at a time (default 1; each row's train_s is then that of a loaded machine).
On one core, as train_s is quoted in the docs: taskset -c 1 python3 tools/robust_seeds.py ... --jobs 1

train_headless is found on PATH, else by catkin_find (source devel/setup.bash), or given with
--train-headless.
Nothing is written (--no-run-folder).
"""
import argparse
import os
import concurrent.futures
import re
import shutil
import statistics
import subprocess
import sys


def seeds(text):
    """'0-19', '1,17,19' or both ('0-4,9'): the seeds in the order given."""
    chosen = []
    try:
        for part in text.split(','):
            low, _, high = part.strip().partition('-')
            chosen.extend(range(int(low), int(high or low) + 1))
    except ValueError:
        raise argparse.ArgumentTypeError("%s is not a list of seeds such as 0-19 or 1,17,19" % text)
    if not chosen:
        raise argparse.ArgumentTypeError("%s names no seed" % text)
    return chosen


def find_train_headless():
    """train_headless on PATH, else where catkin puts it (devel/lib/cartpole_qlearning: not on PATH)."""
    found = shutil.which('train_headless')
    if found:
        return found
    try:
        out = subprocess.run(['catkin_find', '--first-only', '--libexec', 'cartpole_qlearning', 'train_headless'],
                             capture_output=True, text=True).stdout.split()
    except OSError:
        out = []
    return out[0] if out else 'train_headless'


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--config', required=True)
    parser.add_argument('--seeds', type=seeds, default=seeds('0-19'))
    parser.add_argument('--train-headless', default=find_train_headless())
    parser.add_argument('--jobs', type=int, default=1, help='seeds trained at a time (default 1)')
    args = parser.parse_args()
    if args.jobs < 1:
        parser.error('--jobs %d: at least 1' % args.jobs)

    def train(seed):
        # Reaped here (os.wait4) for the run's own CPU time: train_s is wall time, which a busy
        # machine stretches; the two agree on a quiet core.
        proc = subprocess.Popen([args.train_headless, '--config', args.config, '--seed', str(seed), '--no-run-folder'],
                                stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        out = proc.stdout.read()
        proc.stdout.close()
        _, _, usage = os.wait4(proc.pid, 0)
        proc.returncode = 0
        train_s = re.search(r' train_s=([0-9.]+) ', out)
        end = re.search(r'^(SUITE PASSED|suite NOT passed|SOLVED|NOT solved)\S* .*?after (\d+) episodes, (\d+) steps',
                        out, re.M)
        verdict = [l for l in out.splitlines() if re.search(r': (PASSED|FAILED)$', l) and ' at episode ' not in l]
        if verdict:
            cases = re.findall(r'(\w+) (\d+)/(\d+)', verdict[-1])
            passed = verdict[-1].endswith('PASSED')
            said = verdict[-1]
        else:
            # A run trained until solved prints its table's verdict as a table, for information:
            # a row per case ("nominal  0/1  100  874.0  FAIL ..."), then "N of M cases pass".
            summary = re.search(r'^(\d+) of (\d+) cases pass', out, re.M)
            cases = re.findall(r'^(\w+) +(\d+)/(\d+) +\d+ ', out, re.M)
            passed = bool(summary) and summary.group(1) == summary.group(2)
            said = summary.group(0) if summary else ''
        if not end or not cases or not train_s:
            sys.exit('seed %d: no verdict in the output:\n%s' % (seed, out))
        print('seed %d: %s' % (seed, said), file=sys.stderr, flush=True)
        return dict(seed=seed, passed=passed, episodes=int(end.group(2)),
                    steps=int(end.group(3)), train_s=float(train_s.group(1)),
                    cpu=usage.ru_utime + usage.ru_stime, cases=[(n, int(b)) for n, b, _ in cases])

    # A seed without a verdict stops the whole run at once (sys.exit in a worker thread would only
    # surface after every queued seed had trained): the seeds not started are cancelled.
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = [pool.submit(train, seed) for seed in args.seeds]
        try:
            rows = [future.result() for future in futures]
        except SystemExit:
            for future in futures:  # (cancel_futures= needs Python 3.9; Noetic's Ubuntu has 3.8)
                future.cancel()
            raise
    names = [n for n, _ in rows[0]['cases']]
    print('| seed | passes | episodes | steps | train_s | cpu s | ' + ' | '.join(names) + ' |')
    print('| --- ' * (6 + len(names)) + '|')
    for r in rows:
        print('| %d | %s | %d | %d | %.1f | %.1f | %s |' % (r['seed'], 'yes' if r['passed'] else '**no**', r['episodes'],
                                                         r['steps'], r['train_s'], r['cpu'], ' | '.join(str(b) for _, b in r['cases'])))
    median = lambda key: statistics.median(r[key] for r in rows)
    print('| median | %d of %d | %.10g | %.10g | %.1f | %.1f | %s |' % (
        sum(r['passed'] for r in rows), len(rows), median('episodes'), median('steps'), median('train_s'), median('cpu'),
        ' | '.join('%.10g' % statistics.median(r['cases'][i][1] for r in rows) for i in range(len(names)))))
    print('| worst | | %d | %d | %.1f | %.1f | %s |' % (
        max(r['episodes'] for r in rows), max(r['steps'] for r in rows), max(r['train_s'] for r in rows),
        max(r['cpu'] for r in rows),
        ' | '.join(str(min(r['cases'][i][1] for r in rows)) for i in range(len(names)))))


if __name__ == '__main__':
    main()
