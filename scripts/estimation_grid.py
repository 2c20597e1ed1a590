#!/usr/bin/python3
"""The doublet grid of docs/estimation.md (issue 48): `fretbuzz.estimate` on synthetic free
decays whose every mode rings as a doublet, over fundamentals, separations, amplitude
ratios, record lengths and SNRs, and on the same decays with one partial per mode.

Each decay is that of tests/SyntheticDecay.hpp with the fundamental changed: modes 1-15 of
a stiff string (B = 1e-4), mode j at j f0 sqrt(1 + B j^2) with sigma_j = 0.5 + 0.3 j /s and
amplitude 0.5 / j; its second partial `separation` higher in relative frequency, at `ratio`
of the amplitude and 0.8 of the damping, phase j rad; 16 kHz; white noise at the SNR given
(of the signal's mean power over the record). At one fundamental, separation, ratio and
length the noise is one draw scaled to each SNR, so that a higher SNR sees the same noise,
only weaker. Every mode 1-15 is checked.

A doublet is "resolved" when its mode has two partials not flagged merged (matched to the
truth by frequency order), "merged" when it has one flagged merged, "lost" otherwise (one
partial not flagged, or none). "Within target": both partials within 2e-5 in frequency and
5 % in damping. A "spurious" partial is a second partial of a mode of a singlet decay.

Run: /usr/bin/python3 scripts/estimation_grid.py [--third] [--table]
(--third: the representative third that tests/test_estimation_grid.cpp checks; --table:
the markdown tables of docs/estimation.md; after building the Python module)
"""
import argparse
import itertools
import math
import sys
import time

import numpy as np

from validation_common import ROOT

sys.path.insert(0, str(ROOT / "build" / "python" / "module"))
import fretbuzz as fb  # noqa: E402

RATE = 16000.0
MODES = 15
B = 1e-4
FUNDAMENTALS = (41.2, 98.0)
SEPARATIONS = (5e-4, 1e-3, 2e-3, 3e-3)
RATIOS = (0.3, 0.8)
LENGTHS = (2.0, 4.0)
SNRS = (40.0, 50.0, 60.0)
FREQUENCY_TARGET, DAMPING_TARGET, DAMPING_LIMIT = 2e-5, 0.05, 0.15


def truth(f0, separation, ratio):
    """(mode, polarisation) -> (frequency, sigma, amplitude, phase); the frequency is that of
    the cosine, the damped one."""
    t = {}
    for j in range(1, MODES + 1):
        f = f0 * j * math.sqrt(1 + B * j * j)
        sigma = 0.5 + 0.3 * j
        t[(j, 1)] = (f, sigma, 0.5 / j, 0.0)
        if ratio > 0:
            t[(j, 2)] = (f * (1 + separation), 0.8 * sigma, ratio * 0.5 / j, 1.0 * j)
    return t


def clean_signal(partials, seconds):
    t = np.arange(int(RATE * seconds)) / RATE
    x = np.zeros_like(t)
    for f, sigma, a, phase in partials.values():
        x += a * np.exp(-sigma * t) * np.cos(2 * np.pi * f * t + phase)
    return x


def seed_of(*key):
    return abs(hash(tuple(round(k * 1e6) for k in key))) % (2 ** 32)


def noisy(x, snr_db, unit_noise):
    return x + unit_noise * math.sqrt(np.mean(x ** 2) * 10 ** (-snr_db / 10))


def estimate(x):
    p = fb.estimate(x, RATE, max_partial=MODES)["partials"]
    merged = p["merged"] if "merged" in p else np.zeros_like(p["mode"])
    out = {}
    for m, f, s, r, g in zip(p["mode"], p["frequency_hz"], p["sigma_per_s"], p["reliable"], merged):
        out.setdefault(int(m), []).append((f, s, r > 0.5, g > 0.5))
    return out


def doublet_outcomes(f0, separation, ratio, seconds, snrs):
    """Per SNR, per mode: a dict of what came back for that doublet."""
    t = truth(f0, separation, ratio)
    x = clean_signal(t, seconds)
    unit = np.random.default_rng(seed_of(f0, separation, ratio, seconds)).standard_normal(x.size)
    results = {}
    for snr in snrs:
        found = estimate(noisy(x, snr, unit))
        modes = {}
        for j in range(1, MODES + 1):
            # The estimator reports undamped frequencies: sqrt(f_d^2 + (sigma / 2 pi)^2).
            true = [(math.hypot(t[(j, k)][0], t[(j, k)][1] / (2 * math.pi)), t[(j, k)][1]) for k in (1, 2)]
            got = sorted(found.get(j, []))
            o = {"beats": true[0][0] * separation * seconds, "errors": [], "reliable_errors": []}
            if len(got) == 2 and not any(g[3] for g in got):
                o["state"] = "resolved"
                for g, tr in zip(got, true):
                    e = (abs(g[0] / tr[0] - 1), abs(g[1] / tr[1] - 1))
                    o["errors"].append(e)
                    if g[2]:
                        o["reliable_errors"].append(e)
            elif len(got) == 1 and got[0][3]:
                o["state"] = "merged"
                o["merged_error"] = abs(got[0][1] / true[0][1] - 1)  # the envelope's damping against the stronger
                if got[0][2]:
                    o["reliable_errors"].append((abs(got[0][0] / true[0][0] - 1), abs(got[0][1] / true[0][1] - 1)))
            else:
                o["state"] = "lost"
                o["lost_as"] = [(abs(g[1] / true[0][1] - 1), g[2]) for g in got]
                for g in got:  # a doublet found as one partial: judged against the stronger
                    if g[2]:
                        o["reliable_errors"].append((abs(g[0] / true[0][0] - 1), abs(g[1] / true[0][1] - 1)))
            o["within"] = o["state"] == "resolved" and all(
                ef <= FREQUENCY_TARGET and es <= DAMPING_TARGET for ef, es in o["errors"])
            modes[j] = o
        results[snr] = modes
    return results


def singlet_outcome(f0, seconds, snr):
    t = truth(f0, 0.0, 0.0)
    x = clean_signal(t, seconds)
    unit = np.random.default_rng(seed_of(f0, 0.0, 0.0, seconds)).standard_normal(x.size)
    found = estimate(noisy(x, snr, unit))
    partials = [(j, g) for j, v in found.items() for g in v]
    true = {j: (math.hypot(t[(j, 1)][0], t[(j, 1)][1] / (2 * math.pi)), t[(j, 1)][1]) for j in range(1, MODES + 1)}
    return {
        "found": len([j for j in found if j <= MODES]),
        "spurious": sum(max(0, len(v) - 1) for v in found.values()) + sum(len(v) for j, v in found.items() if j > MODES),
        "merged": sum(g[3] for _, g in partials),
        "reliable": sum(g[2] for _, g in partials),
        "frequency_error": max(abs(g[0] / true[j][0] - 1) for j, g in partials if j <= MODES),
        "sigma_error": max(abs(g[1] / true[j][1] - 1) for j, g in partials if j <= MODES),
    }


def grid(third):
    cells = list(itertools.product(FUNDAMENTALS, SEPARATIONS, RATIOS, LENGTHS))
    if third:  # every third cell, all SNRs: both fundamentals, every separation, ratio and length
        cells = cells[::3]
    return cells


def efficient_pass_probability(f0, separation, ratio, seconds, snr_db, mode):
    """The chance that an efficient (unbiased, Cramer-Rao) estimate of this doublet lands
    within the targets: both partials' frequencies and dampings, Gaussian with the bound's
    standard deviations, the mode's pair fitted jointly (the other modes lie far in frequency)."""
    t = truth(f0, separation, ratio)
    x = clean_signal(t, seconds)
    variance = np.mean(x ** 2) * 10 ** (-snr_db / 10)
    time = np.arange(x.size) / RATE
    columns = []
    for k in (1, 2):
        f, sigma, a, phase = t[(mode, k)]
        envelope = np.exp(-sigma * time)
        c, s = np.cos(2 * np.pi * f * time + phase), np.sin(2 * np.pi * f * time + phase)
        columns += [envelope * c, -time * a * envelope * c, -2 * np.pi * time * a * envelope * s, -a * envelope * s]
    jacobian = np.array(columns).T
    sd = np.sqrt(np.diag(np.linalg.inv(jacobian.T @ jacobian / variance)))
    p = 1.0
    for k in (1, 2):
        f, sigma = t[(mode, k)][:2]
        p *= math.erf(DAMPING_TARGET * sigma / (sd[4 * (k - 1) + 1] * math.sqrt(2)))
        p *= math.erf(FREQUENCY_TARGET * f / (sd[4 * (k - 1) + 2] * math.sqrt(2)))
    return p


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--third", action="store_true")
    parser.add_argument("--table", action="store_true")
    args = parser.parse_args()
    start = time.perf_counter()
    rows = {}
    for f0, separation, ratio, seconds in grid(args.third):
        for snr, modes in doublet_outcomes(f0, separation, ratio, seconds, SNRS).items():
            rows[(f0, separation, ratio, seconds, snr)] = modes
    summarise(rows, args.table)
    print("\nsinglets (one partial per mode, modes 1-15; both fundamentals):")
    print("| T (s) | SNR (dB) | modes found (of 30) | spurious partials | flagged merged | reliable | "
          "max freq. error | max sigma error (%) |")
    print("|---|---|---|---|---|---|---|---|")
    for seconds, snr in itertools.product(LENGTHS, SNRS):
        found = spurious = merged = reliable = 0
        df = ds = 0.0
        for f0 in FUNDAMENTALS:
            o = singlet_outcome(f0, seconds, snr)
            found += o["found"]
            spurious += o["spurious"]
            merged += o["merged"]
            reliable += o["reliable"]
            df, ds = max(df, o["frequency_error"]), max(ds, o["sigma_error"])
        print(f"| {seconds:g} | {snr:g} | {found} | {spurious} | {merged} | {reliable} | {df:.1e} | {100 * ds:.2f} |")
    print(f"\n[estimation_grid] {time.perf_counter() - start:.1f} s")


def summarise(rows, table):
    target = [(k, j, o) for k, m in rows.items() for j, o in m.items() if o["beats"] >= 2 and k[4] >= 50]
    within = sum(o["within"] for _, _, o in target)
    expected = sum(efficient_pass_probability(*k, j) for k, j, _ in target)
    print(f"Delta f T >= 2, SNR >= 50 dB: {within} of {len(target)} doublets within 2e-5 and 5 % "
          f"({100 * within / max(1, len(target)):.1f} %; an efficient estimator's expectation from the Cramer-Rao "
          f"bound: {expected:.1f}, {100 * expected / max(1, len(target)):.1f} %); "
          f"resolved {sum(o['state'] == 'resolved' for _, _, o in target)}")
    for k, j, o in target:
        if not o["within"]:
            print(f"  outside: f0 {k[0]:g} Hz, separation {100 * k[1]:g} %, ratio {k[2]:g}, {k[3]:g} s, {k[4]:g} dB, "
                  f"mode {j} ({o['state']}): " + ", ".join(f"{a:.1e} and {100 * b:.1f} %" for a, b in o["errors"]) +
                  f"; chance of an efficient estimate inside: {efficient_pass_probability(*k, j):.2f}")
    reliable = [e for m in rows.values() for o in m.values() for e in o["reliable_errors"]]
    over = [(k, j, e) for k, m in rows.items() for j, o in m.items() for e in o["reliable_errors"]
            if e[1] > DAMPING_LIMIT]
    print(f"reliable partials: {len(reliable)}, largest damping error {100 * max(e[1] for e in reliable):.1f} %; "
          f"over 15 %: {len(over)}")
    for k, j, e in over:
        print(f"  {k} mode {j}: sigma error {100 * e[1]:.1f} %, frequency {e[0]:.1e}")
    lost_resolution = []
    for (f0, sep, r, T, snr), m in rows.items():
        for higher in SNRS:
            if higher > snr and (f0, sep, r, T, higher) in rows:
                lost_resolution += [((f0, sep, r, T), j, snr, higher) for j, o in m.items()
                                    if o["state"] == "resolved" and rows[(f0, sep, r, T, higher)][j]["state"] != "resolved"]
    print(f"resolution lost as the SNR grows: {len(lost_resolution)}")
    for item in lost_resolution:
        print("  ", item)
    everything = [o for m in rows.values() for o in m.values()]
    merged = [o for o in everything if o["state"] == "merged"]
    print(f"all {len(everything)} doublets: resolved {sum(o['state'] == 'resolved' for o in everything)}, merged "
          f"{len(merged)} (Delta f T {min((o['beats'] for o in merged), default=0):.2f} to "
          f"{max((o['beats'] for o in merged), default=0):.2f}; damping against the stronger partial up to "
          f"{100 * max((o['merged_error'] for o in merged), default=0):.0f} % off), "
          f"lost {sum(o['state'] == 'lost' for o in everything)}")
    for k, m in rows.items():
        for j, o in m.items():
            if o["state"] == "lost":
                print(f"  lost: {k} mode {j}, Delta f T {o['beats']:.2f}: found as " +
                      (", ".join(f"one partial {100 * e:.1f} % off in damping ({'reliable' if r else 'not reliable'})"
                                 for e, r in o["lost_as"]) or "nothing"))
    if not table:
        return
    print("\n| separation (%) | ratio | T (s) | SNR (dB) | Delta f T, modes 1-15 | resolved | merged | lost | "
          "Delta f T >= 2: within target | max freq. error | max sigma error (%) | reliable: max sigma error (%) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for separation, ratio, seconds, snr in itertools.product(SEPARATIONS, RATIOS, LENGTHS, SNRS):
        cell = [o for f0 in FUNDAMENTALS if (f0, separation, ratio, seconds, snr) in rows
                for o in rows[(f0, separation, ratio, seconds, snr)].values()]
        if not cell:
            continue
        states = [o["state"] for o in cell]
        errors = [e for o in cell for e in o["errors"]]
        rel = [e for o in cell for e in o["reliable_errors"]]
        aimed = [o for o in cell if o["beats"] >= 2]
        print(f"| {100 * separation:g} | {ratio:g} | {seconds:g} | {snr:g} | "
              f"{min(o['beats'] for o in cell):.2f} .. {max(o['beats'] for o in cell):.1f} | "
              f"{states.count('resolved')} | {states.count('merged')} | {states.count('lost')} | "
              f"{sum(o['within'] for o in aimed)} of {len(aimed)} | "
              f"{max((e[0] for e in errors), default=0):.1e} | {100 * max((e[1] for e in errors), default=0):.1f} | "
              f"{100 * max((e[1] for e in rel), default=0):.1f} |")


if __name__ == "__main__":
    main()
