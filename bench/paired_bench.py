#!/usr/bin/env python3
"""Two fretbuzz_bench builds side by side in one session: the same benchmarks, run by each in
turn for several rounds, so that the load of a shared machine falls on both alike. Prints, per
benchmark row, the median over all rounds and repetitions of each build's CPU time and wall
time, and the ratio new / old of the CPU medians (on a loaded machine wall time also counts the
waits for a core; CPU time is the thread's own work).

    bench/paired_bench.py --rounds 3 OLD/fretbuzz_bench NEW/fretbuzz_bench \\
        --benchmark_filter='^(Fast|Straightforward|Window|Outputs|None|Played)/' --benchmark_repetitions=5
    bench/paired_bench.py --rounds 5 OLD/fretbuzz_bench NEW/fretbuzz_bench --contact 9 'sitar bridge'

Google Benchmark rows come from its JSON output (the repetitions' own rows, not their
aggregates; a program that reports aggregates only, fretbuzz_bench_realtime, gives its medians); `--contact` rows from the tables it prints (each line '| label | ... | CPU | wall |'
whose last two cells are numbers: the table's medians of its repetitions).
"""
import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from collections import defaultdict
from pathlib import Path


def run(program, args):
    rows = defaultdict(lambda: ([], []))  # label -> (cpu values, wall values)
    if "--contact" in args:
        out = subprocess.run([program] + args, capture_output=True, text=True, check=True).stdout
        for line in out.splitlines():
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if len(cells) < 3:
                continue
            try:
                cpu, wall = float(cells[-2]), float(cells[-1])
            except ValueError:
                continue
            rows[cells[0]][0].append(cpu)
            rows[cells[0]][1].append(wall)
        return rows
    with tempfile.TemporaryDirectory() as scratch:
        path = Path(scratch) / "out.json"
        subprocess.run([program] + args + [f"--benchmark_out={path}", "--benchmark_out_format=json"],
                       stdout=subprocess.DEVNULL, check=True)
        medians = defaultdict(lambda: ([], []))  # for programs that report aggregates only
        for b in json.loads(path.read_text())["benchmarks"]:
            scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b.get("time_unit", "ns")]
            if b.get("run_type") == "iteration":
                target = rows
            elif b.get("aggregate_name") == "median":
                target = medians
            else:
                continue
            target[b["run_name"]][0].append(b["cpu_time"] * scale)
            target[b["run_name"]][1].append(b["real_time"] * scale)
        for label, values in medians.items():
            if label not in rows:
                rows[label] = values
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("old")
    parser.add_argument("new")
    options, args = parser.parse_known_args()
    results = {"old": defaultdict(lambda: ([], [])), "new": defaultdict(lambda: ([], []))}
    order = []
    for r in range(options.rounds):
        for which, program in (("old", options.old), ("new", options.new)):
            for label, (cpu, wall) in run(program, args).items():
                results[which][label][0].extend(cpu)
                results[which][label][1].extend(wall)
                if label not in order:
                    order.append(label)
        print(f"round {r + 1} of {options.rounds} done", file=sys.stderr)
    unit = "table's unit" if "--contact" in args else "ms"
    print(f"| row | old CPU ({unit}) | new CPU ({unit}) | new/old CPU | old wall | new wall | samples |")
    print("|---|---|---|---|---|---|---|")
    for label in order:
        old, new = results["old"][label], results["new"][label]
        if not old[0] or not new[0]:
            continue
        oc, nc = statistics.median(old[0]), statistics.median(new[0])
        ow, nw = statistics.median(old[1]), statistics.median(new[1])
        print(f"| {label} | {oc:.4g} | {nc:.4g} | {nc / oc:.3f} | {ow:.4g} | {nw:.4g} | {len(old[0])}/{len(new[0])} |")


if __name__ == "__main__":
    main()
