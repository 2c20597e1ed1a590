#!/usr/bin/python3
"""Validation of `fretbuzz estimate` (docs/estimation.md):

1. bass-pluck without contact, 48 kHz, 3 s, at its observation point: the first 30 modes'
   frequencies and dampings against the case's own mode table, clean and with white noise
   at 60 dB and 40 dB SNR (the Python module's fretbuzz.estimate on the NumPy signal);
2. round trip: `fretbuzz estimate` on the run's audio.wav with --case bass-pluck writes
   case.toml; re-running it reproduces the original displacement to the relative L2 error
   printed, over the first 0.5 s (whole band, and below the highest measured partial);
3. a real recording: the nylon-guitar low E sample of Debian's freepats package
   (scripts/freepats_decay.py extracts it), its f0 against the sample's root note, B and Q;
4. doublets: synthetic decays whose every mode rings in two polarisations, the second
   partial a relative `separation` higher, at 0.6 of the amplitude and 0.8 of the damping,
   in white noise: how many of modes 3-12 keep both partials and with what errors, against
   separation, SNR and duration.

Run: /usr/bin/python3 scripts/validate_estimation.py [noise|round-trip|real|doublets]...
(all four without arguments; after building fretbuzz and its module)
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
    for row in second:
        first = p[p[:, 0] == row[0]][0]
        print(f"  mode {int(row[0])}: doublet {row[1] - first[1]:+.3f} Hz ({100 * (row[1] / first[1] - 1):+.3f} %), "
              f"amplitude ratio {row[4] / first[4]:.2f}, sigma {first[2]:.3f} and {row[2]:.3f} 1/s"
              f"{'' if row[8] > 0.5 else ' (weak)'}")
    d = fit["damping_model"]
    print(f"  damping fit: delta_ve = {d['delta_ve']:.3e}, 1/Q_te = {d['Q_te_inv']:.3e}, sigma rms error "
          f"{100 * d['sigma_rms_relative_error']:.0f} %")


def doublet_decay(separation, snr_db, seconds, rng, f0=110.0, modes=15, rate=16000.0):
    """The synthetic decay of tests/SyntheticDecay.hpp: mode j at j f0 sqrt(1 + B j^2),
    sigma_j = 0.5 + 0.3 j, amplitude 0.5 / j; its doublet partial separation higher, 0.6 of
    the amplitude, 0.8 of the damping. Returns the signal and the true partials by
    (mode, polarisation)."""
    t = np.arange(int(rate * seconds)) / rate
    x = np.zeros_like(t)
    truth = {}
    for j in range(1, modes + 1):
        f = f0 * j * math.sqrt(1 + 1e-4 * j * j)
        sigma = 0.5 + 0.3 * j
        for polarisation, (fj, sj, aj, phase) in ((1, (f, sigma, 0.5 / j, 0.0)),
                                                 (2, (f * (1 + separation), 0.8 * sigma, 0.3 / j, 1.0 * j))):
            x += aj * np.exp(-sj * t) * np.cos(2 * np.pi * fj * t + phase)
            truth[(j, polarisation)] = (fj, sj)
    x += rng.normal(0.0, math.sqrt(np.mean(x ** 2) * 10 ** (-snr_db / 10)), x.size)
    return x, rate, truth


def doublet_errors(separation, snr_db, seconds, rng, first=3, last=12):
    """Modes first..last: how many keep both partials, the largest relative errors of those
    partials, and the largest sigma error (against the stronger partial) of a mode found as
    one partial."""
    x, rate, truth = doublet_decay(separation, snr_db, seconds, rng)
    p = fb.estimate(x, rate, max_partial=15)["partials"]
    found = {(int(m), int(k)): (f, s) for m, k, f, s in
             zip(p["mode"], p["polarisation"], p["frequency_hz"], p["sigma_per_s"])}
    both, df, ds, merged = 0, 0.0, 0.0, 0.0
    for j in range(first, last + 1):
        if (j, 2) in found and (j, 1) in found:
            both += 1
            for k in (1, 2):
                f, s = found[(j, k)]
                df = max(df, abs(f / truth[(j, k)][0] - 1))
                ds = max(ds, abs(s / truth[(j, k)][1] - 1))
        elif (j, 1) in found:
            merged = max(merged, abs(found[(j, 1)][1] / truth[(j, 1)][1] - 1))
    return both, df, ds, merged


SEPARATIONS = (1e-4, 2e-4, 4e-4, 1e-3, 2e-3, 5e-3)
SNRS = (30.0, 40.0, 50.0, 60.0)


def beats(separation, seconds, mode):
    """Delta f T of that mode's doublet: the number of beats in the record."""
    return 110.0 * mode * math.sqrt(1 + 1e-4 * mode * mode) * separation * seconds


def doublet_study():
    rng = np.random.default_rng(38)
    seconds = 3.0
    print(f"\ndoublets, {seconds:g} s at 16 kHz, f0 = 110 Hz, modes 3-12:")
    print("| separation (%) | Delta f T, mode 3 .. 12 | SNR (dB) | both partials (of 10) | max freq. error | "
          "max sigma error (%) | merged: max sigma error (%) |")
    print("|---|---|---|---|---|---|---|")
    for separation in SEPARATIONS:
        for snr in SNRS:
            both, df, ds, merged = doublet_errors(separation, snr, seconds, rng)
            print(f"| {100 * separation:g} | {beats(separation, seconds, 3):.2f} .. {beats(separation, seconds, 12):.2f} "
                  f"| {snr:g} | {both} | {df:.1e} | {100 * ds:.1f} | {100 * merged:.0f} |")
    # The smallest Delta f T at which a doublet is still resolved, from every mode of every
    # separation: per duration and SNR, the smallest Delta f T above which all were.
    print("\nsmallest separation above which every doublet of modes 1-12 was resolved (both partials within "
          "1e-4 in frequency and 15 % in sigma), Delta f in Hz (Delta f T):")
    print("| SNR (dB) | " + " | ".join(f"T = {t:g} s" for t in (1.0, 3.0)) + " |")
    print("|---|---|---|")
    for snr in SNRS:
        row = []
        for seconds in (1.0, 3.0):
            failed = []
            for separation in SEPARATIONS:
                x, rate, truth = doublet_decay(separation, snr, seconds, rng)
                p = fb.estimate(x, rate, max_partial=15)["partials"]
                found = {(int(m), int(k)): (f, s) for m, k, f, s in
                         zip(p["mode"], p["polarisation"], p["frequency_hz"], p["sigma_per_s"])}
                for j in range(1, 13):
                    ok = all((j, k) in found and abs(found[(j, k)][0] / truth[(j, k)][0] - 1) <= 1e-4 and
                             abs(found[(j, k)][1] / truth[(j, k)][1] - 1) <= 0.15 for k in (1, 2))
                    if not ok:
                        failed.append(beats(separation, seconds, j))
            row.append(f"{max(failed) / seconds:.2f} Hz ({max(failed):.2f})" if failed else "all")
        print(f"| {snr:g} | " + " | ".join(row) + " |")


def main():
    parts = sys.argv[1:] or ["noise", "round-trip", "real", "doublets"]
    work = scratch_dir("estimation")
    if "noise" in parts:
        noise_study(work)
    if "round-trip" in parts:
        round_trip(work)
    if "real" in parts:
        real_recording(work)
    if "doublets" in parts:
        doublet_study()


if __name__ == "__main__":
    main()
