"""Set-up map throughput from Python: notes per second of the bass-neck buzz map
(fretbuzz.Bench on the bass-neck instrument: a 2 mm pop, one pluck per note, 4 MHz, 0.5 s,
as the case-based set-up study computed it) on 1 and on 2 threads, side by side in one
process, alternating the order in each repetition; prints each time, the medians, notes per
second and the 1 -> 2 speed-up (ratio of the medians). A note is its simulation and its
obstacle-free reference. Also the CPU time the process used and CPU/wall (the cores it
actually got): on a shared machine a speed-up below 2 with CPU/wall near 1 means the second
core was busy elsewhere.

    PYTHONPATH=build/python/module /usr/bin/python3 bench/bench_sweep.py [--frets 0-19]
        [--duration 0.5] [--fs 4e6] [--repetitions 3] [--notes clamp|finger|both] [--workers 1,2]

--notes picks the stopped-note model of `fretbuzz setup`: the string clamped on the fret
(the stand-in, the default) or a finger pressing it (`--finger`); `both` times the two maps
side by side, alternating, on the same threads (a fretted note costs far more: free flight
is off while a finger is on the string).
"""
import argparse
import os
import resource
import statistics
import sys
import time

import fretbuzz


def frets_of(text: str):
    frets = []
    for part in text.split(","):
        a, _, b = part.partition("-")
        frets += list(range(int(a), int(b or a) + 1))
    return frets


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--instrument", default="bass-neck")
    p.add_argument("--frets", default="0-19", help="e.g. 0-19 (the notes the case-based study played)")
    p.add_argument("--duration", type=float, default=0.5)
    p.add_argument("--fs", type=float, default=4e6)
    p.add_argument("--repetitions", type=int, default=3)
    p.add_argument("--notes", choices=("clamp", "finger", "both"), default="clamp")
    p.add_argument("--workers", default="1,2", help="thread counts to time, e.g. 1,2 or 2")
    a = p.parse_args()
    frets = frets_of(a.frets)
    models = ("clamp", "finger") if a.notes == "both" else (a.notes,)
    workers = [int(w) for w in a.workers.split(",")]
    series = [(model, jobs) for model in models for jobs in workers]
    benches = {(model, jobs): fretbuzz.Bench(a.instrument, strengths="pop", finger=model == "finger", jobs=jobs,
                                              ensemble=1, fs=a.fs, duration=a.duration) for model, jobs in series}
    times = {s: [] for s in series}
    cpu = {s: [] for s in series}
    for r in range(a.repetitions):
        for model, jobs in (series if r % 2 == 0 else series[::-1]):
            usage = resource.getrusage(resource.RUSAGE_SELF)
            start = time.perf_counter()
            table = benches[model, jobs].map(frets=frets)
            times[model, jobs].append(time.perf_counter() - start)
            after = resource.getrusage(resource.RUSAGE_SELF)
            cpu[model, jobs].append(after.ru_utime + after.ru_stime - usage.ru_utime - usage.ru_stime)
            assert (table["status"] == "ok").all(), table[table["status"] != "ok"]
            print(f"repetition {r + 1}, {model} notes, {jobs} thread(s): {times[model, jobs][-1]:.2f} s wall, "
                  f"{cpu[model, jobs][-1]:.2f} s CPU", flush=True)
    print(f"\n{a.instrument}: {a.duration:g} s per note at {a.fs:g} Hz, medians of {a.repetitions} repetitions, "
          f"os.cpu_count() = {os.cpu_count()}")
    medians = {s: statistics.median(times[s]) for s in series}
    for model, jobs in series:
        m, c = medians[model, jobs], statistics.median(cpu[model, jobs])
        print(f"{model} notes ({len(frets)}, frets {frets[0]}-{frets[-1]}), {jobs} thread{'s' if jobs > 1 else ' '}: "
              f"{m:.2f} s, {len(frets) / m:.3f} notes/s, CPU {c:.2f} s, CPU/wall {c / m:.2f}")
    for model in models:
        if 1 in workers and 2 in workers:
            print(f"{model} notes: speed-up 1 -> 2 threads: {medians[model, 1] / medians[model, 2]:.2f}x")
    if len(models) == 2:
        for jobs in workers:
            print(f"{jobs} thread(s): finger map / clamp map: {medians['finger', jobs] / medians['clamp', jobs]:.1f}x the time")
    return 0


if __name__ == "__main__":
    sys.exit(main())
