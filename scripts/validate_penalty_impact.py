#!/usr/bin/python3
"""The penalty against its rigid limit on the bass pop: `fretbuzz run bass-pop` with the penalty
at K = 1e9 ... 1e17 (alpha 1.5) and with Newton's impact law (e = 0 and e = 1), at 4 MHz over
the paper's 0.3 s window; prints the relative L2 distance of each penalty run's observation
(x = 0.854 m, 48 kHz rows) to the impact runs', and their contact times (first and last contact,
steps in contact). Then (unless --no-speed) the paired speed of the 3 s pop, impact law against
penalty, medians of --reps runs each, alternated in one session; and the rigid pop's energy
figure, docs/figures/bass-rigid-frets-energy.png.
Usage: validate_penalty_impact.py [--duration 0.3] [--reps 3] [--no-speed]"""
import argparse
import json
import shutil
import statistics

import numpy as np

from validation_common import FIGURES, fretbuzz, processor, read_csv, relative_l2, scratch_dir


def run(out, *options):
    fretbuzz("run", "bass-pop", "-q", "--out", out, *options)
    summary = json.loads((out / "summary.json").read_text())
    _, data = read_csv(out / "observation.csv")
    return data[:, 1], summary


BANDS = ((0.0, 1000.0), (1000.0, 5000.0), (5000.0, 24000.0))  # Hz


def band_distances(a, b, rate):
    """Relative L2 distance of the magnitude spectra of a and b in each of BANDS."""
    n = min(len(a), len(b))
    sa, sb = np.abs(np.fft.rfft(a[:n])), np.abs(np.fft.rfft(b[:n]))
    f = np.fft.rfftfreq(n, 1.0 / rate)
    return [float(np.linalg.norm((sa - sb)[(f >= lo) & (f < hi)]) / np.linalg.norm(sb[(f >= lo) & (f < hi)]))
            for lo, hi in BANDS]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--duration", default="0.3")
    parser.add_argument("--reps", type=int, default=3)
    parser.add_argument("--no-speed", action="store_true")
    args = parser.parse_args()
    out = scratch_dir("penalty-impact")
    impact = {e: run(out / f"impact-{e}", "--duration", args.duration, "--law", "impact", "--restitution", e)
              for e in ("0", "1")}
    rows = []
    for k in ("1e9", "1e11", "1e13", "1e15", "1e17"):
        u, s = run(out / f"K{k}", "--duration", args.duration, "--K", k)
        rows.append((k, relative_l2(u, impact["0"][0]), relative_l2(u, impact["1"][0]), s,
                     band_distances(u, impact["0"][0], float(s["output_rate"]))))
    fs = float(impact["0"][1]["fs"])
    print(f"\nbass pop, {args.duration} s at {fs / 1e6:g} MHz, 862 modes; observation at 0.854 m (48 kHz rows)")
    print("| law | relative L2 to impact e = 0 | to impact e = 1 | first contact (ms) | last contact (ms) | "
          "steps in contact |")
    print("|---|---|---|---|---|---|")
    for k, to0, to1, s, _ in rows:
        print(f"| penalty K = {k} | {to0:.3g} | {to1:.3g} | {1e3 * s['first_contact_s']:.4f} | "
              f"{1e3 * s['last_contact_s']:.3f} | {s['contact_steps']} |")
    print(f"| impact e = 1 (against e = 0) | {relative_l2(impact['1'][0], impact['0'][0]):.3g} | | | | |")
    for e, (_, s) in impact.items():
        print(f"| impact e = {e} | | | {1e3 * s['first_contact_s']:.4f} | {1e3 * s['last_contact_s']:.3f} | "
              f"{s['contact_steps']} |")
    print("\nmagnitude spectra against impact e = 0, relative L2 in each band:")
    print("| law | " + " | ".join(f"{lo / 1e3:g}-{hi / 1e3:g} kHz" for lo, hi in BANDS) + " |")
    print("|---|" + "---|" * len(BANDS))
    for k, _, _, _, bands in rows:
        print(f"| penalty K = {k} | " + " | ".join(f"{d:.3g}" for d in bands) + " |")
    e1 = band_distances(impact["1"][0], impact["0"][0], float(impact["1"][1]["output_rate"]))
    print("| impact e = 1 | " + " | ".join(f"{d:.3g}" for d in e1) + " |")
    # The rigid pop's energy: each slap on a fret takes its step (docs/figures/bass-rigid-frets-energy.png).
    fretbuzz("run", "bass-rigid-frets", "-q", "--duration", "0.05", "--out", out / "figure")
    fretbuzz("plot", out / "figure")
    shutil.copy(out / "figure" / "energy.png", FIGURES / "bass-rigid-frets-energy.png")
    if args.no_speed:
        return
    walls = {"penalty": [], "impact": []}
    for _ in range(args.reps):  # alternated, so that both laws see the same machine state
        walls["penalty"].append(run(out / "speed-penalty", "--duration", "3")[1]["wall_seconds"])
        walls["impact"].append(run(out / "speed-impact", "--duration", "3", "--law", "impact")[1]["wall_seconds"])
    penalty, impact_wall = statistics.median(walls["penalty"]), statistics.median(walls["impact"])
    print(f"\n3 s bass pop at 4 MHz, run wall time, median of {args.reps} alternated runs on {processor()}: "
          f"penalty {penalty:.2f} s, impact (e = 0) {impact_wall:.2f} s: {impact_wall / penalty:.1f}x")


if __name__ == "__main__":
    main()
