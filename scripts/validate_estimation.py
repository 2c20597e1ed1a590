#!/usr/bin/python3
"""Validation of `fretbuzz estimate` (docs/estimation.md):

1. bass-pluck without contact, 48 kHz, 3 s, at its observation point: the first 30 modes'
   frequencies and dampings against the case's own mode table, clean and with white noise
   at 60 dB and 40 dB SNR (the Python module's fretbuzz.estimate on the NumPy signal);
2. round trip: `fretbuzz estimate` on the run's audio.wav with --case bass-pluck writes
   case.toml; re-running it reproduces the original displacement to the relative L2 error
   printed, over the first 0.5 s (whole band, and below the highest measured partial);
3. a real recording: the nylon-guitar low E sample of Debian's freepats package
   (scripts/freepats_decay.py extracts it), its f0 against the sample's root note, B and Q,
   its doublets and merged ones.
Doublets on synthetic decays: scripts/estimation_grid.py.

Run: /usr/bin/python3 scripts/validate_estimation.py [noise|round-trip|real]...
(all three without arguments; after building fretbuzz and its module)
"""
import json
import math
import subprocess
import sys

import numpy as np

from validation_common import ROOT, fretbuzz, read_csv, scratch_dir

sys.path.insert(0, str(ROOT / "build" / "python" / "module"))
import fretbuzz as fb  # noqa: E402

BASS = {"L": 0.863, "mu": 6.69e-3, "d": 1.14e-3, "T": 191.6}
FREEPATS = "/usr/share/midi/freepats/Tone_000/024_Nylon_Guitar.pat"


def bass_pluck(directory, duration, case="bass-pluck"):
    fretbuzz("run", case, "--fs", 48000, "--allow-aliasing", "--duration", duration, "-q", "--out", directory)
    _, data = read_csv(directory / "observation.csv")
    return data[:, 1]


def table_of(case):
    _, data = read_csv_text(fretbuzz("modes", case, capture=True))
    return data


def read_csv_text(text):
    rows = [r.split(",") for r in text.strip().splitlines()]
    return rows[0], np.array([[float(v) for v in r[:3]] for r in rows[1:]])


def noise_study(work):
    x = bass_pluck(work / "clean", 3.0)
    truth = table_of("bass-pluck")
    rng = np.random.default_rng(2017)
    power = np.mean(x ** 2)
    print("\n| signal | partials found (of 30) | reliable | max freq. error (%) | median sigma error (%) | max sigma error (%) | max sigma error, reliable (%) |")
    print("|---|---|---|---|---|---|---|")
    for label, snr in (("clean", None), ("60 dB SNR", 60.0), ("40 dB SNR", 40.0)):
        y = x if snr is None else x + rng.normal(0.0, math.sqrt(power * 10 ** (-snr / 10)), x.size)
        e = fb.estimate(y, 48000.0, max_partial=30)
        p = e["partials"]
        j = p["mode"].astype(int)
        df = np.abs(p["frequency_hz"] / truth[j - 1, 1] - 1) * 100
        ds = np.abs(p["sigma_per_s"] / truth[j - 1, 2] - 1) * 100
        rel = p["reliable"] > 0.5
        print(f"| {label} | {len(j)} | {int(rel.sum())} | {df.max():.2e} | {np.median(ds):.3f} | {ds.max():.2f} | "
              f"{ds[rel].max():.2f} |")


def round_trip(work):
    original = bass_pluck(work / "rt_run", 3.0)
    fretbuzz("estimate", work / "rt_run" / "audio.wav", "--case", "bass-pluck", "--d", BASS["d"], "--no-plots", "-q",
             "--out", work / "rt_est")
    fit = json.loads((work / "rt_est" / "fit.json").read_text())
    n = int(0.5 * 48000)
    again = bass_pluck(work / "rt_again", 0.5, str(work / "rt_est" / "case.toml"))[:n]
    reference = original[:n]
    full = np.linalg.norm(again - reference) / np.linalg.norm(reference)
    # The part of the signal below the highest measured partial (models above it).
    top = fit["mode_table"]["measured_up_to"]
    cutoff = top * fit["frequency_model"]["f0_hz"] * 1.02
    f = np.fft.rfftfreq(n, 1 / 48000)

    def low(s):
        spectrum = np.fft.rfft(s)
        spectrum[f > cutoff] = 0
        return np.fft.irfft(spectrum, n)

    below = np.linalg.norm(low(again) - low(reference)) / np.linalg.norm(low(reference))
    print(f"\nround trip over 0.5 s: relative L2 error {full:.3e} (whole band), {below:.3e} below {cutoff:.0f} Hz "
          f"(measured modes 1..{top}; {fit['mode_table']['measured']} measured of {fit['mode_table']['modes']}); "
          f"{fit['partials']['found']} partials found, {fit['partials']['doublets']} doublets, "
          f"B = {fit['frequency_model']['B']:.3e}")


def real_recording(work):
    wav = work / "nylon_e2.wav"
    subprocess.run([sys.executable, str(ROOT / "scripts" / "freepats_decay.py"), str(wav)], check=True)
    # A classical guitar's low E: L = 0.65 m; mu from T ~ 70 N at 82.4 Hz; d ~ 1.1 mm.
    fretbuzz("estimate", wav, "--L", 0.65, "--mu", 6.0e-3, "--d", 1.1e-3, "--max-partial", 60, "-q",
             "--out", work / "nylon")
    fit = json.loads((work / "nylon" / "fit.json").read_text())
    p = np.loadtxt(work / "nylon" / "partials.csv", delimiter=",", comments="#")
    second = p[p[:, 9] == 2]
    merged = p[p[:, 12] > 0.5]
    p = p[p[:, 9] == 1]  # each mode's stronger partial
    rel = p[:, 8] > 0.5
    f1 = p[p[:, 0] == 1, 1]
    print(f"\nfreepats {FREEPATS}, sample e1 (root 82.399 Hz, E2):")
    print(f"  partials found {len(p)}, reliable {int(rel.sum())}: modes {', '.join(str(int(m)) for m in p[rel, 0])}")
    if len(f1):
        print(f"  mode 1 at {f1[0]:.3f} Hz ({1200 * math.log2(f1[0] / 82.399):+.1f} cents from the root note)")
    fm = fit["frequency_model"]
    print(f"  law: f0 = {fm['f0_hz']:.3f} Hz ({1200 * math.log2(fm['f0_hz'] / 82.399):+.1f} cents), B = {fm['B']:.3e}, "
          f"rms {fm['rms_cents']:.2f} cents")
    q = p[rel, 3]
    print(f"  Q of the reliable partials: median {np.median(q):.0f}, range {q.min():.0f} to {q.max():.0f}")
    print(f"  doublets resolved: {len(second)}; merged (too close to resolve): {len(merged)}, modes "
          f"{', '.join(str(int(m)) for m in merged[:, 0])}")
    for row in second:
        first = p[p[:, 0] == row[0]][0]
        print(f"  mode {int(row[0])}: doublet {row[1] - first[1]:+.3f} Hz ({100 * (row[1] / first[1] - 1):+.3f} %, "
              f"{(row[1] - first[1]) * fit['recording']['decay_duration_s']:+.2f} beats), "
              f"amplitude ratio {row[4] / first[4]:.2f}, sigma {first[2]:.3f} +- {first[11]:.3f} and "
              f"{row[2]:.3f} +- {row[11]:.3f} 1/s{'' if row[8] > 0.5 else ' (not reliable)'}")
    d = fit["damping_model"]
    print(f"  damping fit: delta_ve = {d['delta_ve']:.3e}, 1/Q_te = {d['Q_te_inv']:.3e}, sigma rms error "
          f"{100 * d['sigma_rms_relative_error']:.0f} %")


def main():
    parts = sys.argv[1:] or ["noise", "round-trip", "real"]
    work = scratch_dir("estimation")
    if "noise" in parts:
        noise_study(work)
    if "round-trip" in parts:
        round_trip(work)
    if "real" in parts:
        real_recording(work)


if __name__ == "__main__":
    main()
