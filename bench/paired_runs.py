#!/usr/bin/env python3
"""Wall time of whole `fretbuzz run` (or `fretbuzz setup`) commands, variants side by side in one session.

Each repetition runs every variant once, in turn, so that the load of a shared machine
falls on all of them alike; the table gives the median wall time of each variant (over
the repetitions), seconds of wall time per simulated second, and the ratio to the first
variant. A variant is `label=program args...` with the program's path first, e.g.

    bench/paired_runs.py --reps 5 \\
        'before=/path/old/fretbuzz run tanpura --fs 48000 --allow-aliasing' \\
        'after=build/cli/fretbuzz run tanpura --fs 48000 --allow-aliasing'

Each run writes into a fresh scratch directory (--out is added), removed afterwards.
"""
import argparse
import json
import resource
import shlex
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def run_once(command, out_dir):
    # CPU time (user + system of the child) as well: on a shared machine wall time also
    # counts the waits for a core.
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    result = subprocess.run(command + ["--out", str(out_dir)], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if result.returncode != 0:
        sys.exit(f"{shlex.join(command)} failed ({result.returncode}): {result.stderr.strip()}")
    summary_file = out_dir / "summary.json"  # a run's; a set-up map has none (no seconds simulated)
    summary = json.loads(summary_file.read_text()) if summary_file.exists() else {}
    return wall, cpu, summary


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--reps", type=int, default=5)
    parser.add_argument("--simulated", type=float, default=float("nan"),
                        help="simulated seconds of runs that write no summary.json (strings on a bridge)")
    parser.add_argument("variants", nargs="+", help="label=program args...")
    args = parser.parse_args()
    variants = []
    for text in args.variants:
        label, _, command = text.partition("=")
        variants.append((label, shlex.split(command)))
    walls = {label: [] for label, _ in variants}
    cpus = {label: [] for label, _ in variants}
    simulated = {}
    with tempfile.TemporaryDirectory(prefix="fretbuzz-bench-") as scratch:
        for rep in range(args.reps):
            for v, (label, command) in enumerate(variants):
                out_dir = Path(scratch) / f"{rep}-{v}"
                wall, cpu, summary = run_once(command, out_dir)
                walls[label].append(wall)
                cpus[label].append(cpu)
                simulated[label] = summary.get("duration", args.simulated)
                subprocess.run(["rm", "-rf", str(out_dir)], check=True)
    first = statistics.median(walls[variants[0][0]])
    first_cpu = statistics.median(cpus[variants[0][0]])
    print(f"{'variant':<24} {'median wall s':>14} {'s per sim s':>12} {'ratio':>7} {'median CPU s':>13} "
          f"{'CPU per sim s':>14} {'ratio':>7}   (medians of {args.reps} paired runs)")
    for label, _ in variants:
        median = statistics.median(walls[label])
        cpu = statistics.median(cpus[label])
        print(f"{label:<24} {median:14.3f} {median / simulated[label]:12.4f} {median / first:7.2f} {cpu:13.3f} "
              f"{cpu / simulated[label]:14.4f} {cpu / first_cpu:7.2f}")


if __name__ == "__main__":
    main()
