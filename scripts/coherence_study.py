#!/usr/bin/env python3
"""How robust are the late touches of the high frets? The bench's string keeps every partial at
its exact inharmonic frequency, so the partials drift out of harmonic phase and meet again, and a
stopped string can swing further toward the frets than its release shape, long after release.
Real partials stray from any smooth law; the paper's measured G string departs from its fitted
B law by 0.8-1.3 cents rms over its first 10-40 modes (shared data, bass_fretted_modes.csv).

This replays the Jazz Bass's E and G strings at frets 12-15 (medium pluck) with every stopped
note's partials detuned at random by 0 (the model), the measured rms and larger ones, and
prints each note's verdict, clean_up_to and first touch as a Markdown table.

    python3 scripts/coherence_study.py [--fretbuzz build/cli/fretbuzz] [--scatter 0,1,3,10]
"""
import argparse
import csv
import os
import subprocess
import sys
import tempfile


def play(fretbuzz, scatter, out, strings, frets):
    cmd = [fretbuzz, "setup", "jazz-bass", "--out", out, "--strings", strings, "--frets", frets,
           "--strength", "medium", "--partial-scatter", str(scatter), "--quiet"]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    with open(os.path.join(out, "buzz_map.csv"), newline="") as f:
        return {(r["string"], int(r["fret"])): r for r in csv.DictReader(f)}


def cell(r):
    up_to = r["clean_up_to"]
    up_to = "-" if up_to == "" else ("3+" if up_to == "inf" else f"{float(up_to):.2f}")
    touch = r["first_touch_s"]
    touch = "-" if touch in ("", "nan") else f"{float(touch) * 1e3:.0f} ms"
    return f"{r['verdict']} {up_to}x, {touch}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--fretbuzz", default="build/cli/fretbuzz")
    parser.add_argument("--scatter", default="0,1,3,10", help="rms detunings to try, in cents")
    parser.add_argument("--strings", default="E,G")
    parser.add_argument("--frets", default="12-15")
    args = parser.parse_args()
    scatters = [float(s) for s in args.scatter.split(",")]
    maps = {}
    with tempfile.TemporaryDirectory() as tmp:
        for s in scatters:
            maps[s] = play(args.fretbuzz, s, os.path.join(tmp, f"s{s}"), args.strings, args.frets)
    notes = sorted(maps[scatters[0]], key=lambda k: (args.strings.split(",").index(k[0]), k[1]))
    print("| note | " + " | ".join(f"{s:g} cents" for s in scatters) + " |")
    print("|---|" + "---|" * len(scatters))
    for k in notes:
        print(f"| {k[0]}{k[1]} | " + " | ".join(cell(maps[s][k]) for s in scatters) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
