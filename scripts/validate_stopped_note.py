#!/usr/bin/python3
"""A stopped note: the partials of the bass stopped at frets 1, 5, 12 and 15, four ways
(docs/validation.md, section 7, "The held string"):

- reference: the case's own modes (`fretbuzz modes CASE`) with u(x_k) = 0 imposed, the string
  going on over the fret to the nut, computed here from scratch with numpy: the dense
  eigenproblem diag(omega_j^2) + z z^T / R (z_j = phi_j(x_k); R the static compliance of the
  modes above the table, the dispersion extrapolated past it as c^2 linear in k^2), the
  near-side overlaps integrated exactly, and the near side damped (zeta = 0.2, and 0.05 and
  0.5 to show that the partials do not depend on it) over every held mode up to 1.5 times the
  partial at once; the partial is the complex mode with most of its energy on the far side
  nearest to the pinned piece's;
- pinned stand-in: the piece from x_k to the bridge pinned at both ends (its inharmonicity
  B' = B (L / L')^2), as `fretbuzz setup` rebuilt it and the former stopped_string without
  the B fix (every frequency times L / L');
- held stand-in: stopped_string(), fretbuzz's stand-in now (printed by the example program
  build/examples/stopped_note);
- finger: `fretbuzz run` with `fret = k` (the lumped finger of scheme/Finger.hpp pressing the
  string onto fret k with 5 N) and the case's pop, made gentle (0.3 mm) so that the string
  stays off the other frets, at the case's Fe = 4 MHz for 1.5 s; each partial from u(0.854 m)
  over 0.5-1.5 s (after the near side's fast transient), shifted to 0 Hz, decimated to 480 Hz
  and fitted by a matrix pencil (the pole within 30 cents of the partial with the most energy over the window). Where u at a point
  of the near side (37 % of the way to the fret) has a mode of its own within 30 cents of the
  partial, stronger there than the partial, the partial is marked as mixed with the near side
  (a dagger in the table). A star on a reference partial: the held string's undamped modes
  mix the two sides there (near-side share between 0.02 and 0.98 within 30 cents), which the
  near side's damping undoes.

Run: /usr/bin/python3 scripts/validate_stopped_note.py [--jobs N]   (8 finger runs: about
45 s of computing per simulated second each, 1.5 s simulated). --write-runs DIR writes the
finger runs' case files and the commands to run them (runs.sh) and stops; --runs DIR reads the
runs' observation.csv files made there (DIR/<name>/observation.csv) instead of running them.
"""
import argparse
import math
import time
import os
import re
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CASES = ROOT / "cases"
FRETS = (1, 5, 12, 15)
PARTIALS = 10
CASE_NAMES = ("bass-neck", "bass-pop")
DURATION = 1.5
POP = 0.3e-3  # m: the gentle pop's release displacement
ZETAS = (0.2, 0.05, 0.5)  # the first is the one fretbuzz uses (HeldString::kNearSideDampingRatio)


def binary(name):
    for build in ("build-valid", "build", "build-release"):
        candidate = ROOT / build / name
        if candidate.exists():
            return str(candidate)
    sys.exit(f"{name} not found: build it (cmake --build build --target {Path(name).name})")


# ---- the finger runs (no numpy needed: they may run on another machine) ----

def finger_case_text(case, fret, data):
    """The case with `fret = k` and a gentle pop after the finger has settled; `data`: the
    cases' data folder as the case file will see it."""
    fretted = (CASES / "bass-fret5-pop.toml").read_text()
    gesture = fretted[fretted.index("\n[[gesture]]") + 1:]
    gesture = re.sub(r"release_displacement = [^\n]*", f"release_displacement = {POP}", gesture)
    if case == "bass-pop":
        text = fretted.replace("fret = 5", f"fret = {fret}")
        text = re.sub(r"release_displacement = [^\n]*", f"release_displacement = {POP}", text)
    else:
        text = (CASES / f"{case}.toml").read_text()
        text = re.sub(r"\[excitation\][^\[]*", '[excitation]\ntype = "sine"\nmode = 1\namplitude = 0.0\n\n', text)
        text = f"fret = {fret}\n" + text + "\n" + gesture
    # A second observation point on the near side (37 % of the way to the fret), where the
    # near side's own modes show.
    near = 0.37 * 0.863 * (1 - 2 ** (-fret / 12))
    text = text.replace("x = [0.854]", f"x = [0.854, {near:.4f}]")
    return text.replace('"data/', f'"{data}/')


def write_runs(directory):
    directory.mkdir(parents=True, exist_ok=True)
    commands = []
    for case in CASE_NAMES:
        for fret in FRETS:
            name = f"{case}-fret{fret}"
            data = os.path.relpath(CASES / "data", directory.resolve())
            (directory / f"{name}.toml").write_text(finger_case_text(case, fret, data))
            commands.append(f'"$FRETBUZZ" run "$DIR/{name}.toml" --duration {DURATION} --out "$DIR/{name}" -q')
    (directory / "runs.sh").write_text(
        'DIR=$(cd "$(dirname "$0")" && pwd); FRETBUZZ=${FRETBUZZ:-fretbuzz}\n' +
        "".join(f"{c} &\n" for c in commands) + "wait\n")
    return directory


def run_fingers(directory, jobs):
    write_runs(directory)
    fretbuzz = binary("cli/fretbuzz")
    names = [f"{c}-fret{k}" for c in CASE_NAMES for k in FRETS]

    def one(name):
        if (directory / name / "observation.csv").exists():
            return
        command = [fretbuzz, "run", str(directory / f"{name}.toml"), "--duration", str(DURATION), "--out",
                   str(directory / name), "-q"]
        print("$", " ".join(command), flush=True)
        subprocess.run(command, check=True)

    with ThreadPoolExecutor(jobs) as pool:
        list(pool.map(one, names))


# ---- analysis ----

def stand_in(case):
    """stopped_note's rows: {fret: (stop, [pinned], [held])}."""
    out = subprocess.run([binary("examples/stopped_note"), case, *map(str, FRETS)], check=True, text=True,
                         capture_output=True).stdout.splitlines()[1:]
    table = {}
    for line in out:
        _, fret, stop, _, pinned, held, _, _ = line.split(",")
        entry = table.setdefault(int(fret), (float(stop), [], []))
        entry[1].append(float(pinned))
        entry[2].append(float(held))
    return table


def open_modes(case):
    import numpy as np
    out = subprocess.run([binary("cli/fretbuzz"), "modes", case], check=True, text=True, capture_output=True).stdout
    rows = [line.split(",") for line in out.splitlines()[1:]]
    return np.array([float(r[1]) for r in rows]), np.array([float(r[2]) for r in rows])


def static_compliance(freq, length, stop):
    """sum over the modes above the table of z_j^2 / omega_j^2, c^2 extrapolated linearly in k^2."""
    import numpy as np
    n = len(freq)
    j = np.arange(1, n + 1)
    k = j * math.pi / length
    c2 = (2 * math.pi * freq / k) ** 2
    top = slice(n - max(2, n // 8), n)
    slope = max(0.0, np.polyfit(k[top] ** 2, c2[top], 1)[0])
    jt = np.arange(n + 1, 64 * n + 1)
    kt = jt * math.pi / length
    c2t = c2[-1] + slope * (kt ** 2 - k[-1] ** 2)
    total = np.sum(2 / length * np.sin(kt * stop) ** 2 / (kt ** 2 * c2t))
    kk = (64 * n + 0.5) * math.pi / length
    a = c2[-1] - slope * k[-1] ** 2
    if slope > 0 and a > 0:
        y = math.sqrt(a / slope) / kk
        g = y * y / 3 - y ** 4 / 5 if y < 1e-3 else 1 - math.atan(y) / y
        return total + g / (math.pi * a * kk)
    return total + 1 / (math.pi * kk * (a + slope * kk ** 2))


def reference(freq, sigma, length, stop, guesses):
    """The held string's first partials (see the module's docstring), for each zeta, and the
    undamped held modes with their near-side shares."""
    import numpy as np
    n = len(freq)
    j = np.arange(1, n + 1)
    z = math.sqrt(2 / length) * np.sin(j * math.pi * stop / length)
    d = (2 * math.pi * freq) ** 2
    r = static_compliance(freq, length, stop)
    w, v = np.linalg.eigh(np.diag(d) + np.outer(z, z) / r)
    w, v = w[:-1], v[:, :-1]  # the top one is the spring's own
    held_f = np.sqrt(w) / (2 * math.pi)
    m = int(np.searchsorted(held_f, 1.5 * max(guesses))) + 1
    v = v[:, :m]
    t = math.pi * stop / length
    jj, kk = np.meshgrid(j, j, indexing="ij")
    with np.errstate(divide="ignore", invalid="ignore"):
        g = (np.sin((jj - kk) * t) / (jj - kk) - np.sin((jj + kk) * t) / (jj + kk)) / math.pi
    g[j - 1, j - 1] = (t - np.sin(2 * j * t) / (2 * j)) / math.pi
    near = v.T @ g @ v
    damping = v.T @ (sigma[:, None] * v)
    shares = np.diag(near)
    result = {}
    for zeta in ZETAS:
        partials = []
        for guess in guesses:
            mm = int(np.searchsorted(held_f[:m], 1.5 * guess))
            omega = 2 * math.pi * guess
            a = np.zeros((2 * mm, 2 * mm))
            a[:mm, mm:] = np.eye(mm)
            a[mm:, :mm] = -np.diag((held_f[:mm] / guess) ** 2)
            a[mm:, mm:] = -(2 / omega) * damping[:mm, :mm] - 2 * zeta * near[:mm, :mm]
            lam, vec = np.linalg.eig(a)
            best, pick = None, None
            for i in range(2 * mm):
                if lam[i].imag <= 0:
                    continue
                y = vec[:mm, i]
                if np.real(np.conj(y) @ near[:mm, :mm] @ y) / np.real(np.conj(y) @ y) >= 0.5:
                    continue
                f = abs(lam[i]) * guess
                if best is None or abs(math.log(f / guess)) < best:
                    best, pick = abs(math.log(f / guess)), f
            partials.append(pick)
        result[zeta] = partials
    return result, held_f[:m], shares


def pencil(signal, dt, guess):
    """Poles near `guess` of a sampled signal: (frequency, energy over the window) of each."""
    import numpy as np
    import scipy.signal as ss
    y = signal * np.exp(-2j * math.pi * guess * dt * np.arange(len(signal)))
    y = ss.decimate(ss.decimate(y, 10, ftype="fir", zero_phase=True), 10, ftype="fir", zero_phase=True)[20:-20]
    step = 100 * dt
    rows = len(y) // 2
    hankel = np.array([y[i:i + rows + 1] for i in range(len(y) - rows)])
    vh = np.linalg.svd(hankel, full_matrices=False)[2][:16].T
    poles = np.linalg.eigvals(np.linalg.pinv(vh[:-1]) @ vh[1:])
    amplitude = np.abs(np.linalg.lstsq(np.vander(poles, len(y), increasing=True).T, y, rcond=None)[0])
    # Each pole's energy over the window (a fast-decaying pole's large initial amplitude counts less).
    energy = amplitude ** 2 * np.array([np.sum(np.abs(p) ** (2 * np.arange(len(y)))) for p in poles])
    f = guess + np.angle(poles) / (2 * math.pi * step)
    return [(f[i], energy[i]) for i in range(len(poles)) if f[i] > 0 and abs(cents(f[i], guess)) < 30]


def finger_partials(observation, guesses):
    """(frequency, mixed) of each partial from u(t) (see the module's docstring)."""
    import numpy as np
    data = np.loadtxt(observation, delimiter=",", skiprows=1)
    keep = data[:, 0] >= 0.5
    dt = data[1, 0] - data[0, 0]
    far, near = (data[keep, c] - data[keep, c].mean() for c in (1, 2))
    out = []
    for guess in guesses:
        f = max(pencil(far, dt, guess), key=lambda p: p[1])[0]
        # Mixed: on the near side, a mode of its own (more than a cent away) within 30 cents
        # that is stronger there than the partial.
        poles = pencil(near, dt, guess)
        here = max((e for g, e in poles if abs(cents(g, f)) <= 1.0), default=0.0)
        mixed = any(abs(cents(g, f)) > 1.0 and e > here for g, e in poles)
        out.append((f, mixed))
    return out


def cents(a, b):
    return 1200 * math.log2(a / b)


def analyse(runs):
    import numpy as np
    summary = {"held": 0.0, "pinned": [], "finger": [], "finger_mixed": 0, "zeta": 0.0}
    for case in CASE_NAMES:
        freq, sigma = open_modes(case)
        length = 0.863
        table = stand_in(case)
        print(f"\n**{case}** (cents from the reference; partials 1-10)\n")
        print("| fret | x_k (m) | | " + " | ".join(str(n) for n in range(1, PARTIALS + 1)) + " |")
        print("|---|---|---|" + "---|" * PARTIALS)
        for fret in FRETS:
            stop, pinned, held = table[fret]
            ref, held_modes, shares = reference(freq, sigma, length, stop, pinned)
            best = ref[ZETAS[0]]
            spread = max(abs(cents(a, b)) for z in ZETAS[1:] for a, b in zip(ref[z], best))
            summary["zeta"] = max(summary["zeta"], spread)
            kept_b = [freq[n] * length / (length - stop) for n in range(PARTIALS)]
            rows = [("reference (Hz)", [f"{f:.2f}" for f in best])]
            rows.append(("pinned, B kept", [f"{cents(a, b):+.2f}" for a, b in zip(kept_b, best)]))
            rows.append(("pinned, B'", [f"{cents(a, b):+.2f}" for a, b in zip(pinned, best)]))
            rows.append(("held stand-in", [f"{cents(a, b):+.2f}" for a, b in zip(held, best)]))
            summary["held"] = max(summary["held"], max(abs(cents(a, b)) for a, b in zip(held, best)))
            summary["pinned"] += [cents(a, b) for a, b in zip(pinned, best)]
            observation = runs / f"{case}-fret{fret}" / "observation.csv"
            if observation.exists():
                finger = finger_partials(observation, held)
                cells = []
                for (f, mixed), b in zip(finger, best):
                    cells.append(f"{cents(f, b):+.2f}" + ("†" if mixed else ""))
                    if mixed:
                        summary["finger_mixed"] += 1
                    else:
                        summary["finger"].append(cents(f, b))
                rows.append(("finger", cells))
            # Partials whose undamped held modes mix the two sides (the reference de-mixes them).
            mixed_ref = [any(abs(cents(h, b)) < 30 and 0.02 < s < 0.98 for h, s in zip(held_modes, shares)) for b in best]
            for label, cells in rows:
                if label == "reference (Hz)":
                    cells = [c + ("*" if m else "") for c, m in zip(cells, mixed_ref)]
                print(f"| {fret if label.startswith('reference') else ''} | "
                      f"{f'{stop:.3f}' if label.startswith('reference') else ''} | {label} | " + " | ".join(cells) + " |")
    pinned = np.array(summary["pinned"])
    print(f"\nheld stand-in: largest |cents| from the reference {summary['held']:.3f}")
    print(f"pinned (B'): {pinned.min():+.2f} to {pinned.max():+.2f} cents from the reference")
    if summary["finger"]:
        finger = np.array(summary["finger"])
        print(f"finger (unmixed partials): {finger.min():+.2f} to {finger.max():+.2f} cents, "
              f"{np.mean(np.abs(finger) <= 1.0) * 100:.0f} % within 1 cent; {summary['finger_mixed']} partials mixed")
    print(f"reference: largest change with zeta = 0.05 or 0.5 instead of 0.2: {summary['zeta']:.3f} cents")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--jobs", type=int, default=2, help="finger runs at a time")
    parser.add_argument("--runs", type=Path, help="read the finger runs from this directory")
    parser.add_argument("--write-runs", type=Path, help="write the finger runs' case files and runs.sh here and stop")
    a = parser.parse_args()
    if a.write_runs:
        write_runs(a.write_runs)
        print(f"written: {a.write_runs}/runs.sh (FRETBUZZ=/path/to/fretbuzz sh {a.write_runs}/runs.sh)")
        return
    runs = a.runs
    if runs is None:
        runs = ROOT / "build" / "stopped-note-runs"
        run_fingers(runs, a.jobs)
    analyse(runs)
    print(f"run time: {time.perf_counter() - START:.0f} s")


START = time.perf_counter()

if __name__ == "__main__":
    main()
