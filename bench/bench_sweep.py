"""Sweep throughput: runs per second of a neck set-up study (the bass-neck buzz map) on 1
and on 2 local workers, side by side in one process, alternating the order in each
repetition; prints each time, the medians, runs per second and the 1 -> 2 speed-up (ratio
of the medians). A run is one note: its simulation and its obstacle-free reference.
Also the CPU time the process used and CPU/wall (the cores it actually got): on a shared
machine a speed-up below 2 with CPU/wall near 1 means the second core was busy elsewhere.

    PYTHONPATH=build/python/module /usr/bin/python3 bench/bench_sweep.py [--frets 0-19]
        [--duration 0.5] [--fs 4e6] [--repetitions 3] [--notes clamp|finger|both] [--workers 1,2]

--notes picks the stopped-note model of `fretbuzz setup`: the string clamped on the fret
(the default) or a finger pressing it (`--finger`); `both` times the two maps side by side,
alternating, on the same workers (a fretted note costs far more: free flight is off while a
finger is on the string).
"""
import argparse
import os
import resource
import statistics
import sys
import tempfile
import time

import fretbuzz
from fretbuzz import _core, neck


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--case", default="bass-neck")
    p.add_argument("--frets", default=None, help="e.g. 0-19 (default: every playable fret)")
    p.add_argument("--duration", type=float, default=0.5)
    p.add_argument("--fs", type=float, default=4e6)
    p.add_argument("--repetitions", type=int, default=3)
    p.add_argument("--notes", choices=("clamp", "finger", "both"), default="clamp")
    p.add_argument("--workers", default="1,2", help="worker counts to time, e.g. 1,2 or 2")
    a = p.parse_args()
    n = neck.Neck(fretbuzz.load_case(a.case).source_text, a.case)
    fixed = {"run.fs": a.fs, "run.duration": a.duration}
    specs = {}
    for model in (("clamp", "finger") if a.notes == "both" else (a.notes,)):
        fingered = model == "finger"
        if a.frets:
            frets = neck._frets(a.frets, n, fingered)
        else:
            frets = [k for k in range(n.N + 1 if fingered else n.N)
                     if not fingered or k == 0 or n.fret_x(k) < min([n.pluck_x, *n.observe])]
        make = neck.fingered_study_spec if fingered else neck.study_spec
        text = make(n, a.case, frets, [n.amplitude], fixed).replace("audio = true", "audio = false")
        specs[model] = (_core.SweepSpec.parse(text, "bench", "."), frets)
    workers = [int(w) for w in a.workers.split(",")]
    series = [(model, jobs) for model in specs for jobs in workers]
    times = {s: [] for s in series}
    cpu = {s: [] for s in series}
    with tempfile.TemporaryDirectory(prefix="fretbuzz-bench-") as tmp:
        for r in range(a.repetitions):
            for model, jobs in (series if r % 2 == 0 else series[::-1]):
                usage = resource.getrusage(resource.RUSAGE_SELF)
                start = time.perf_counter()
                outcome = fretbuzz.sweeps.run_sweep(specs[model][0], os.path.join(tmp, f"{r}-{model}-{jobs}"),
                                                    jobs=jobs)
                times[model, jobs].append(time.perf_counter() - start)
                after = resource.getrusage(resource.RUSAGE_SELF)
                cpu[model, jobs].append(after.ru_utime + after.ru_stime - usage.ru_utime - usage.ru_stime)
                assert outcome["failed"] == 0, outcome
                print(f"repetition {r + 1}, {model} notes, {jobs} worker(s): {times[model, jobs][-1]:.2f} s wall, "
                      f"{cpu[model, jobs][-1]:.2f} s CPU", flush=True)
    print(f"\n{a.case}: {a.duration:g} s per note at {a.fs:g} Hz, medians of {a.repetitions} repetitions, "
          f"os.cpu_count() = {os.cpu_count()}")
    medians = {s: statistics.median(times[s]) for s in series}
    for model, jobs in series:
        spec, frets = specs[model]
        m, c = medians[model, jobs], statistics.median(cpu[model, jobs])
        print(f"{model} notes ({len(spec)}, frets {frets[0]}-{frets[-1]}), {jobs} worker{'s' if jobs > 1 else ' '}: "
              f"{m:.2f} s, {len(spec) / m:.3f} runs/s, CPU {c:.2f} s, CPU/wall {c / m:.2f}")
    for model in specs:
        if 1 in workers and 2 in workers:
            print(f"{model} notes: speed-up 1 -> 2 workers: {medians[model, 1] / medians[model, 2]:.2f}x")
    if len(specs) == 2:
        for jobs in workers:
            print(f"{jobs} worker(s): finger map / clamp map: "
                  f"{medians['finger', jobs] / medians['clamp', jobs]:.1f}x the time")
    return 0


if __name__ == "__main__":
    sys.exit(main())
