#!/usr/bin/python3
"""A finger stopping the bass (issue: playing the string): the pitch of notes stopped at frets
1, 5, 7 and 12 against f_open L / (L - x_k), and the energy balance with fingers and a thumb.

Pitch: the Jazz Bass of bass-pluck on 255 modes (dx = 3.4 mm) at fs = 100 kHz, plucked
0.2 mm at 0.637 m, stopped with `--fret k` (the default finger: 5 N after 5 ms); the
fundamental is the peak of the Hann-windowed spectrum of u(0.854 m) over 0.3-1.3 s. Two mode
tables: the measured one of the case, and the exact stiff-string model nu_j = j nu_0
sqrt(1 + B j^2) with the case's B = 3.5e-5, then B = 0 and 4 B, and 511 modes (where the model
table's few cents come from). Energy: the built-in finger cases at 400 kHz
for 1e5 steps (0.25 s; the lifted finger 0.6 s; guitar-pluck at its 2 MHz), with and without losses (the fretted cases popped at 20 ms by a plucker, guitar-pluck
plucked by a plectrum): summary.json's largest |H - W + D - H0|
over the run relative to the larger of H0 and the work W.
Run: /usr/bin/python3 scripts/validate_fingers.py   (about 3 minutes on one core)"""
import json
import math

import numpy as np

from validation_common import CASES, fretbuzz, read_csv, scratch_dir

L = 0.863
MODES = 255
FS = 100000.0
RATE = 10000.0
MODEL_MODES = """[modes.frequency]
model = "inharmonic"

[modes.damping]
model = "physical"
delta_ve = 0.01
Q_te_inv = 6e-6
"""


def small_bass(directory, model, stiffness="3.5e-5", modes=MODES):
    text = (CASES / "bass-pluck.toml").read_text()
    text = text.replace("modes = 862", f"modes = {modes}").replace("amplitude = 0.5e-3", "amplitude = 0.2e-3")
    if model:
        text = text.replace('[modes]\ntable = "data/bass_fretted_modes.csv"\n', MODEL_MODES)
        text = text.replace("mu = 6.69e-3", f"mu = 6.69e-3\nB = {stiffness}\nd = 1.14e-3")
    path = directory / (f"model-B{stiffness}-N{modes}.toml" if model else "measured.toml")
    path.write_text(text)
    return path


def fundamental(case, directory, expected, fret=None, fs=FS):
    out = directory / f"run-{case.stem}-{fret}"
    args = ["run", case, "--fs", fs, "--duration", 1.3, "--output-rate", RATE, "--out", out, "-q",
            "--allow-aliasing"]
    if fret:
        args += ["--fret", fret]
    fretbuzz(*args)
    _, data = read_csv(out / "observation.csv")
    u = data[data[:, 0] >= 0.3, 1]
    n = len(u)
    window = 0.5 - 0.5 * np.cos(2 * np.pi * np.arange(n) / n)
    k = np.arange(n)

    def magnitude(f):
        return abs(np.sum(window * u * np.exp(-2j * np.pi * f / RATE * k)))

    grid = np.arange(0.97 * expected, 1.03 * expected, 0.02)
    m = np.array([magnitude(f) for f in grid])
    i = int(np.argmax(m))
    a, b, c = magnitude(grid[i] - 0.02), m[i], magnitude(grid[i] + 0.02)
    return grid[i] + 0.5 * 0.02 * (a - c) / (a - 2 * b + c)


def fret_position(k, modes=MODES):
    # The fretboard generator puts the grid point nearest to S (1 - 2^(-k/12)) on fret k.
    dx = L / (modes + 1)
    return round(L * (1 - 2 ** (-k / 12)) / dx) * dx


def pitch_table(directory):
    print("\n| mode table | fret | x_k (m) | f_open (Hz) | expected (Hz) | simulated (Hz) | error (cents) |")
    print("|---|---|---|---|---|---|---|")
    for model in (True, False):
        case = small_bass(directory, model)
        f_open = fundamental(case, directory, 98.0)
        for k in (1, 5, 7, 12):
            x = fret_position(k)
            expected = f_open * L / (L - x)
            f = fundamental(case, directory, expected, k)
            cents = 1200 * math.log2(f / expected)
            name = "stiff-string model" if model else "measured"
            print(f"| {name} | {k} | {x:.4f} | {f_open:.3f} | {expected:.3f} | {f:.3f} | {cents:+.2f} |")


def stiffness_and_grid_table(directory):
    """Where the model table's few cents come from: the stopped note against the string's
    bending stiffness B (0, the case's 3.5e-5, 4x) and the grid (255 and 511 modes)."""
    print("\n| B | modes | fs (Hz) | fret | expected (Hz) | simulated (Hz) | error (cents) |")
    print("|---|---|---|---|---|---|---|")
    for stiffness, modes, fs in (("0", 255, FS), ("3.5e-5", 255, FS), ("1.4e-4", 255, FS),
                                 ("0", 511, 2 * FS), ("3.5e-5", 511, 2 * FS)):
        case = small_bass(directory, True, stiffness, modes)
        f_open = fundamental(case, directory, 98.0, fs=fs)
        for k in (1, 12):
            expected = f_open * L / (L - fret_position(k, modes))
            f = fundamental(case, directory, expected, k, fs=fs)
            print(f"| {stiffness} | {modes} | {fs:.0f} | {k} | {expected:.3f} | {f:.3f} | "
                  f"{1200 * math.log2(f / expected):+.2f} |")


def energy_table(directory):
    print("\n| case | losses | steps | work W (J) | finger loss (J) | max |H - W + D - H0| / max(H0, W) |")
    print("|---|---|---|---|---|---|")
    for case in ("bass-fret5-pop", "bass-fret12-pop", "bass-fret5-lift", "bass-slap", "guitar-pluck"):
        for lossless in (True, False):
            out = directory / f"energy-{case}-{lossless}"
            duration = 0.6 if case == "bass-fret5-lift" else 0.25  # the lift comes at 0.5 s
            fs = 2e6 if case == "guitar-pluck" else 400000  # guitar-pluck at its own 2 MHz
            args = ["run", case, "--fs", fs, "--duration", duration, "--allow-aliasing", "--out", out, "-q"]
            if lossless:
                args.append("--lossless")
            fretbuzz(*args)
            s = json.loads((out / "summary.json").read_text())
            print(f"| {case} | {'--lossless' if lossless else 'as given'} | {s['steps']} | {s['work_J']:.4g} | "
                  f"{s['finger_loss_J']:.4g} | {s['max_relative_energy_balance_error']:.2e} |")


if __name__ == "__main__":
    scratch = scratch_dir("fingers")
    pitch_table(scratch)
    stiffness_and_grid_table(scratch)
    energy_table(scratch)
