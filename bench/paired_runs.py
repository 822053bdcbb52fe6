#!/usr/bin/python3
"""Times two commands in alternation (A B A B ...) and prints each one's wall, CPU and peak memory
(min, median, max) and the ratio A/B taken pair by pair, so that a machine whose speed drifts
during the runs still gives a meaningful ratio. Quote the medians.

  bench/paired_runs.py -n 3 --vs "COMMAND_B ..." -- COMMAND_A ...

Each command is split as a shell splits words (B from its string, A from the arguments after
--) and run without a shell; its output goes to /dev/null unless --log-dir is given. A warm-up
run of each (not counted) comes first unless --warmup 0.
"""
import argparse
import os
import shlex
import statistics
import subprocess
import sys
import time


def run_once(command, log):
    """Runs command to completion; returns (wall s, user + system s, peak RSS MiB of the largest process)."""
    start = time.monotonic()
    with open(log, "ab") if log else open(os.devnull, "wb") as out:
        child = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=out, stderr=subprocess.STDOUT)
        _, status, usage = os.wait4(child.pid, 0)
    wall = time.monotonic() - start
    code = os.waitstatus_to_exitcode(status)
    if code != 0:
        sys.exit(f"paired_runs: {shlex.join(command)} exited with {code}" + (f" (output in {log})" if log else ""))
    # ru_maxrss (KiB on Linux) is the largest descendant waited for, not a sum.
    return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024.0


def spread(values):
    return f"{statistics.median(values):.3f} ({min(values):.3f}-{max(values):.3f})"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("-n", "--runs", type=int, default=3, help="pairs counted (default 3)")
    parser.add_argument("--warmup", type=int, default=1, help="uncounted runs of each first (default 1)")
    parser.add_argument("--vs", required=True, help="command B (the baseline), one string")
    parser.add_argument("--log-dir", help="append each command's output to A.log and B.log here")
    parser.add_argument("command", nargs=argparse.REMAINDER, help="-- command A and its arguments")
    args = parser.parse_args()
    a = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not a or args.runs < 1 or args.warmup < 0:
        parser.error("give -n >= 1, --warmup >= 0 and command A after --")
    b = shlex.split(args.vs)
    if args.log_dir:
        os.makedirs(args.log_dir, exist_ok=True)
    logs = [os.path.join(args.log_dir, name) if args.log_dir else None for name in ("A.log", "B.log")]
    for _ in range(args.warmup):
        run_once(a, logs[0])
        run_once(b, logs[1])
    figures = {"A": [], "B": []}
    for k in range(args.runs):
        figures["A"].append(run_once(a, logs[0]))
        figures["B"].append(run_once(b, logs[1]))
        print(f"pair {k + 1}: A {figures['A'][-1][0]:.2f} s, B {figures['B'][-1][0]:.2f} s wall", flush=True)
    for name in ("A", "B"):
        wall, cpu, peak = zip(*figures[name])
        print(f"{name}: wall {spread(wall)} s, cpu {spread(cpu)} s, peak {spread(peak)} MiB")
    ratios = [x[0] / y[0] for x, y in zip(figures["A"], figures["B"])]
    print(f"A/B wall, pair by pair: {spread(ratios)}  (B/A median {1.0 / statistics.median(ratios):.2f}x)")


if __name__ == "__main__":
    main()
