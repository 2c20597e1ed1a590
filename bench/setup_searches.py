#!/usr/bin/env python3
"""The set-up bench's searches (the advice, the fret dress), builds side by side in one session.

Each repetition runs every variant once, in turn, so that the load of a shared machine falls
on all of them alike. A variant is `label=program args...`, a `fretbuzz setup` command with
--advice and/or --dress; --out is added. The table gives, per variant, the medians over the
repetitions of the search's own wall time (advice.json's and dress.json's wall_seconds: the
map before them is not counted) and CPU time (cpu_seconds, all threads, where the build gives it), the probes it played, the whole command's wall and CPU time
(CPU: user + system of the child; on a shared machine wall time also counts the waits for a
core), and the ratio of the advice's median to the first variant's. E.g. the Jazz Bass's
advice at one attack against the build before:

    bench/setup_searches.py --reps 3 \\
        'before=/path/old/fretbuzz setup jazz-bass --strength medium --advice --jobs 2 --quiet' \\
        'after=build/cli/fretbuzz setup jazz-bass --strength medium --advice --jobs 2 --quiet'
"""
import argparse
import json
import os
import shlex
import statistics
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import paired_runs  # noqa: E402  (its run_once: one command, its wall and CPU time)


def run_once(command, out_dir):
    wall, cpu, _ = paired_runs.run_once(command, out_dir)
    row = {"wall": wall, "cpu": cpu}
    for name in ("advice", "dress"):
        path = out_dir / f"{name}.json"
        if path.exists():
            found = json.loads(path.read_text())
            row[name] = found["wall_seconds"]
            row[f"{name} probes"] = found["maps_played"]
            if "cpu_seconds" in found:
                row[f"{name} CPU"] = found["cpu_seconds"]
    return row


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--reps", type=int, default=3)
    parser.add_argument("variants", nargs="+", help="label=program args...")
    args = parser.parse_args()
    variants = [(label, shlex.split(command)) for label, _, command in (v.partition("=") for v in args.variants)]
    rows = {label: [] for label, _ in variants}
    with tempfile.TemporaryDirectory(prefix="fretbuzz-bench-") as scratch:
        for rep in range(args.reps):
            for v, (label, command) in enumerate(variants):
                rows[label].append(run_once(command, Path(scratch) / f"{rep}-{v}"))
                print(f"rep {rep + 1} {label}: {rows[label][-1]}", file=sys.stderr, flush=True)
    load = os.getloadavg()[0]
    keys = ("advice", "advice CPU", "advice probes", "dress", "dress CPU", "dress probes", "wall", "cpu")
    print(f"medians of {args.reps} (load average at the end {load:.1f})\n")
    print("| variant | " + " | ".join(k if "probes" in k else f"{k} (s)" for k in keys) + " | advice / first |")
    print("|---|" + "---|" * (len(keys) + 1))
    first = None
    for label, _ in variants:
        med = {k: statistics.median(r[k] for r in rows[label]) if all(k in r for r in rows[label]) else None for k in keys}
        first = first if first is not None else med["advice"]
        ratio = f"{med['advice'] / first:.3f}" if med["advice"] and first else ""
        cells = ["" if med[k] is None else (f"{med[k]:.0f}" if "probes" in k else f"{med[k]:.1f}") for k in keys]
        print(f"| {label} | " + " | ".join(cells) + f" | {ratio} |")


if __name__ == "__main__":
    main()
