#!/usr/bin/env python3
"""The tanpura at a low sampling rate against its converged run: relative L2 difference of
u(0.9 m, t) (observation.csv, written at 48 kHz by both runs) over [0, window].
At --fs 48000 the run keeps the 110 modes below fs/2 (summary.json says so); the reference
keeps all 400 modes at --reference-fs. Every rate is a multiple of the 48 kHz output rate,
so that both runs are read at the same instants.

Usage: FRETBUZZ=build/cli/fretbuzz /usr/bin/python3 scripts/validate_tanpura_rate.py
       [--fs 48000 96000 384000] [--reference-fs 1536000] [--window 0.05 0.1 0.3 1.0]"""
import argparse
import json

import numpy as np

from validation_common import fretbuzz, read_csv, scratch_dir


def observation(directory, fs):
    fretbuzz("run", "tanpura", "--fs", fs, "--out", directory, "-q")
    _, data = read_csv(directory / "observation.csv")
    summary = json.loads((directory / "summary.json").read_text())
    return data, summary


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--fs", type=float, nargs="+", default=[48000.0, 96000.0, 384000.0])
    parser.add_argument("--reference-fs", type=float, default=1536000.0)
    parser.add_argument("--window", type=float, nargs="+", default=[0.05, 0.1, 0.3, 1.0])
    args = parser.parse_args()
    work = scratch_dir("tanpura-rate")
    reference, _ = observation(work / "reference", args.reference_fs)
    print("| fs (Hz) | modes | first contact (s) | " + " | ".join(f"rel. L2 error over {w:g} s" for w in args.window) + " |")
    print("|---|---|---|" + "---|" * len(args.window))
    for fs in args.fs:
        data, summary = observation(work / f"fs{int(fs)}", fs)
        if round(fs) % 48000 != 0:
            raise SystemExit(f"--fs {fs}: must be a multiple of the 48 kHz output rate")
        rows = min(len(data), len(reference))
        errors = []
        for window in args.window:
            keep = data[:rows, 0] <= window + 1e-12
            a, b = data[:rows, 1][keep], reference[:rows, 1][keep]
            errors.append(f"{np.sqrt(np.sum((a - b) ** 2) / np.sum(b ** 2)):.3g}")
        print(f"| {fs:.0f} | {summary['modes']} | {summary['first_contact_s']:.6f} | " + " | ".join(errors) + " |")


if __name__ == "__main__":
    main()
