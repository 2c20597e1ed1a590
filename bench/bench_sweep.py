"""Sweep throughput: runs per second of a neck set-up study (the bass-neck buzz map) on 1
and on 2 local workers, side by side in one process, alternating the order in each
repetition; prints each time, the medians, runs per second and the 1 -> 2 speed-up (ratio
of the medians). A run is one note: its simulation and its obstacle-free reference.
Also the CPU time the process used and CPU/wall (the cores it actually got): on a shared
machine a speed-up below 2 with CPU/wall near 1 means the second core was busy elsewhere.

    PYTHONPATH=build/python/module /usr/bin/python3 bench/bench_sweep.py [--frets 0-19]
        [--duration 0.5] [--fs 4e6] [--repetitions 3]
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
    a = p.parse_args()
    n = neck.Neck(fretbuzz.load_case(a.case).source_text, a.case)
    frets = neck._frets(a.frets, n) if a.frets else list(range(n.N))
    text = neck.study_spec(n, a.case, frets, [n.amplitude], {"run.fs": a.fs, "run.duration": a.duration})
    text = text.replace("audio = true", "audio = false")
    spec = _core.SweepSpec.parse(text, "bench", ".")
    times = {1: [], 2: []}
    cpu = {1: [], 2: []}
    with tempfile.TemporaryDirectory(prefix="fretbuzz-bench-") as tmp:
        for r in range(a.repetitions):
            for jobs in ((1, 2) if r % 2 == 0 else (2, 1)):
                usage = resource.getrusage(resource.RUSAGE_SELF)
                start = time.perf_counter()
                outcome = fretbuzz.sweeps.run_sweep(spec, os.path.join(tmp, f"{r}-{jobs}"), jobs=jobs)
                times[jobs].append(time.perf_counter() - start)
                after = resource.getrusage(resource.RUSAGE_SELF)
                cpu[jobs].append(after.ru_utime + after.ru_stime - usage.ru_utime - usage.ru_stime)
                assert outcome["failed"] == 0, outcome
                print(f"repetition {r + 1}, {jobs} worker(s): {times[jobs][-1]:.2f} s wall, "
                      f"{cpu[jobs][-1]:.2f} s CPU", flush=True)
    runs = len(spec)
    m1, m2 = statistics.median(times[1]), statistics.median(times[2])
    print(f"\n{a.case}: {runs} notes (frets {frets[0]}-{frets[-1]}), {a.duration:g} s each at {a.fs:g} Hz, "
          f"medians of {a.repetitions} repetitions, os.cpu_count() = {os.cpu_count()}")
    for jobs, m in ((1, m1), (2, m2)):
        c = statistics.median(cpu[jobs])
        print(f"{jobs} worker{'s' if jobs > 1 else ' '}: {m:.2f} s, {runs / m:.3f} runs/s, CPU {c:.2f} s, "
              f"CPU/wall {c / m:.2f}")
    print(f"speed-up 1 -> 2 workers: {m1 / m2:.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
