#!/usr/bin/python3
"""A stopped note: the first 10 partials (frequency and damping) of a bass string stopped at a
fret, three ways (docs/validation.md, section 7, "The held string"):

- reference: the case's own modes (`fretbuzz modes CASE`) with the finger of `fret = k` at rest
  on the string, linearised, computed here from scratch with numpy: the string held at fret k
  (x_k) and at fret k - 1 behind it (the finger between the frets presses it onto both; at
  fret 1 the nut is the string's end), each a stiff spring (the inverse of the static
  compliance between the two points of the modes above the table, the dispersion extrapolated
  past it as c^2 linear in k^2); the held modes by the dense eigenproblem (the springs' own
  left out); the finger's mass M one more coordinate, tied to each of the p grid points of its
  pad by a spring alpha K_f eta^(alpha - 1) / p and a damper lambda F / p (its pad's contact law
  and Hunt-Crossley loss at the compression eta = (F / K_f)^(1 / alpha) of the pressing force
  F); one dense quadratic eigenproblem in state space. Each partial is the complex mode with
  most of its kinetic energy beyond x_k nearest to the pinned piece's partial times the last
  partial's held-to-pinned ratio. Nothing is fitted: M, K_f, alpha, lambda and F are those of
  `fret = k` (FingerSpec's defaults, 5 N);
- held stand-in: stopped_string(), fretbuzz's stand-in (scheme/HeldString.hpp: the same model,
  a window of held modes and the rest as their receptance), printed by the example program
  build/examples/stopped_note with the finger it assumed;
- finger: `fretbuzz run` with the finger of `fret = k` (the lumped finger of scheme/Finger.hpp
  pressing the string with 5 N) at the case's Fe = 4 MHz for 1 s, started from the string
  resting on frets k - 1 and k under the finger's force (the static stiff string, so that
  the long near side is not set ringing against the frets behind), popped gently at 30 ms (a
  pop at the case's pluck point that lets go at the force that lifts the string 0.3 mm, so
  that it stays off the other frets); each partial from u(0.854 m) from 60 ms on, shifted to
  0 Hz, decimated to 480 Hz and fitted by a matrix pencil (the pole within 30 cents of the
  stand-in's partial with the most energy over the window; the window 3 / sigma long, from
  0.08 s to 0.85 s, so that the fast-decaying partials are read while they last).

The cases: bass-neck (modelled modes) and bass-pop (the measured table) at frets 1, 5, 12, 15;
jazz-bass-E, the E string of the jazz-bass instrument (cases/instruments/jazz-bass.toml; its
tension, density and core from the D'Addario set and the assumed core, B = 6.4e-4, 18 times
bass-neck's) on its own neck as `fretbuzz setup` builds it, on 862 modes, at frets 5, 12, 15.

Run: /usr/bin/python3 scripts/validate_stopped_note.py [--jobs N] [--cases jazz-bass-E,...]
(11 finger runs: about 75 s each on a loaded machine). --write-runs DIR writes the finger
runs' case files and the commands to run them (runs.sh) and stops; --runs DIR reads the runs'
observation.csv files made there (DIR/<name>/observation.csv) instead of running them. The
runs' case files need the Python module (build/python/module) for the neck's geometry.
"""
import argparse
import math
import os
import re
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CASES = ROOT / "cases"
FRETS = {"bass-neck": (1, 5, 12, 15), "bass-pop": (1, 5, 12, 15), "jazz-bass-E": (5, 12, 15)}
PARTIALS = 10
DURATION = 1.0
POP_TIME = 0.03   # s
POP = 0.3e-3      # m: what the pop lifts the string by before it lets go
START = 0.06      # s: the partials are read from here (after the pop has let go)
OBSERVE = 0.854   # m
# `fret = k`'s finger: FingerSpec's defaults (include/fretbuzz/Case.hpp) and kFretFingerForce.
FINGER = {"mass": 5e-3, "stiffness": 1e5, "exponent": 1.0, "loss": 20.0, "force": 5.0}


def binary(name):
    for build in ("build-valid", "build", "build-release"):
        candidate = ROOT / build / name
        if candidate.exists():
            return str(candidate)
    sys.exit(f"{name} not found: build it (cmake --build build --target {Path(name).name})")


def fretbuzz_module():
    for build in ("build-valid", "build", "build-release"):
        module = ROOT / build / "python" / "module"
        if (module / "fretbuzz").exists():
            sys.path.insert(0, str(module))
            import fretbuzz
            return fretbuzz
    sys.exit("the Python module is not built (cmake --build build --target fretbuzz_python fretbuzz_python_files)")


# ---- the cases ----

def jazz_bass_e(directory):
    """The jazz-bass instrument's E string on its neck as the bench builds it (StringNeck: the
    board, and each fret's top on its nearest grid point), on a 1 mm grid: a case file."""
    import numpy as np
    fb = fretbuzz_module()
    g = fb.load_instrument("jazz-bass").geometry()[0]
    length, n = g["scale_length_m"], 862
    x = length / (n + 1) * np.arange(1, n + 1)
    rest = g["nut_height_m"] + (g["saddle_height_m"] - g["nut_height_m"]) * x / length
    height = np.interp(x, g["surface_x_m"], g["surface_z_m"]) - rest
    for xf, top in zip(g["fret_x_m"][1:], g["fret_top_m"][1:]):
        i = int(round(xf / (length / (n + 1)))) - 1
        height[i] = top - rest[i]
    directory.mkdir(parents=True, exist_ok=True)
    np.savetxt(directory / "jazz-bass-E-obstacle.csv", np.c_[x, height], delimiter=",", header="x_m,height_m",
               comments="", fmt="%.12e")
    path = directory / "jazz-bass-E.toml"
    path.write_text(f"""# The E string of the jazz-bass instrument on its neck (scripts/validate_stopped_note.py).
name = "jazz-bass-E"
description = "jazz-bass E string: {g['tension_n']:.2f} N, B = {g['inharmonicity']:.3g}"
[string]
L = {length}
T = {g['tension_n']!r}
mu = {g['linear_density']!r}
modes = {n}
E_core_I_core = {g['bending_stiffness']!r}
[modes.frequency]
model = "inharmonic"
[modes.damping]
model = "law"
eta0 = 0.711
eta2 = 2.99e-4
[obstacle]
type = "table"
file = "jazz-bass-E-obstacle.csv"
[excitation]
type = "sine"
mode = 1
amplitude = 0.0
[contact]
K = 1e13
alpha = 1.5
[run]
fs = 4e6
duration = {DURATION}
output_rate = 48000
[observe]
x = [{OBSERVE}]
""")
    return path


def case_path(name, directory):
    return jazz_bass_e(directory) if name == "jazz-bass-E" else CASES / f"{name}.toml"


def stand_in(path, frets):
    """stopped_note's rows: {fret: {stop, behind, pad_centre, pad_width, pinned, held, sigma}}."""
    out = subprocess.run([binary("examples/stopped_note"), str(path), *map(str, frets)], check=True, text=True,
                         capture_output=True).stdout.splitlines()[1:]
    table = {}
    for line in out:
        _, fret, stop, _, pinned, held, sigma, _, behind, centre, width = line.split(",")
        entry = table.setdefault(int(fret), {"stop": float(stop), "behind": float(behind), "pad_centre": float(centre),
                                             "pad_width": float(width), "pinned": [], "held": [], "sigma": []})
        entry["pinned"].append(float(pinned))
        entry["held"].append(float(held))
        entry["sigma"].append(float(sigma))
    return table


def pad_points(centre, width, dx, n):
    """The grid points x_i = (i + 1) dx within width / 2 of centre (numerics/TimeProfile.hpp)."""
    return [i for i in range(n) if abs((i + 1) * dx - centre) <= 0.5 * width * (1 + 1e-12)]


# ---- the finger runs ----

def upper_hull(points):
    hull = []
    for p in points:
        while len(hull) >= 2 and ((hull[-1][1] - hull[-2][1]) * (p[0] - hull[-2][0]) <=
                                  (p[1] - hull[-2][1]) * (hull[-1][0] - hull[-2][0])):
            hull.pop()
        hull.append(p)
    return hull


def resting_shape(case, finger):
    """The string at rest under the finger: on the tops of frets k - 1 and k (and any fret top it
    would cut, on each side), pushed down by F / p at each pad point; the stiff string solved
    statically on the case's modes, the frets it rests on as constraints. u on the grid."""
    import numpy as np
    length, n = case.L, len(case.frequencies)
    dx = length / (n + 1)
    x = dx * np.arange(1, n + 1)
    h = np.asarray(case.obstacle_height)
    # The fret tops: the grid's peaks (a table's frets) and the exact points (crowns at x_n).
    tops = [(x[j], h[j]) for j in range(1, n - 1) if h[j] > h[j - 1] and h[j] > h[j + 1]]
    tops = sorted(tops + [(p[0], p[1]) for p in case.point_obstacles])
    top = lambda at: min(tops, key=lambda p: abs(p[0] - at))
    stop = top(finger["stop"])
    near_end = [(0.0, 0.0)]
    if finger["behind"] > 0.0:
        behind = top(finger["behind"])
        near_end = upper_hull(near_end + [p for p in tops if p[0] < behind[0]] + [behind])
    hull = near_end + upper_hull([stop] + [p for p in tops if p[0] > stop[0]] + [(length, 0.0)])
    holds = [p for p in hull if 0.0 < p[0] < length]
    j = np.arange(1, n + 1)
    phi = lambda xs: math.sqrt(2 / length) * np.sin(np.outer(xs, j) * math.pi / length)
    stiffness = case.mu * (2 * math.pi * np.asarray(case.frequencies)) ** 2
    pad = [(q + 1) * dx for q in pad_points(finger["pad_centre"], finger["pad_width"], dx, n)]
    ph, pp = phi([p[0] for p in holds]), phi(pad)
    push = pp.T @ (-FINGER["force"] / len(pad) * np.ones(len(pad)))
    forces = np.linalg.solve((ph / stiffness) @ ph.T, np.array([p[1] for p in holds]) - (ph / stiffness) @ push)
    return phi(x) @ ((ph.T @ forces + push) / stiffness) + 1e-9


def finger_case_text(name, path, fret, finger, directory):
    """The open case with `fret = k`'s finger pressing from the start, the string at rest under it
    and the gentle pop; its shape file written beside it."""
    import numpy as np
    fb = fretbuzz_module()
    case = fb.load_case(str(path))
    u = resting_shape(case, finger)
    x = case.L / (len(u) + 1) * np.arange(1, len(u) + 1)
    shape = directory / f"{name}-fret{fret}-shape.csv"
    np.savetxt(shape, np.c_[x, u], delimiter=",", header="x_m,u_m", comments="", fmt="%.12e")
    # The pop's pull when the string is POP above its rest: a point force F = d T L' / (a (L' - a)).
    piece, a = case.L - finger["stop"], 0.637 - finger["stop"]
    pull = POP * case.T * piece / (a * (piece - a))
    text = path.read_text()
    text = re.sub(r"\[excitation\][^\[]*", f'[excitation]\ntype = "shape"\nfile = "{shape.name}"\n\n', text)
    text = re.sub(r"duration = [^\n]*", f"duration = {DURATION}", text, count=1)
    text = re.sub(r"x = \[[^\]]*\]", f"x = [{OBSERVE}]", text, count=1)
    data = os.path.relpath(CASES / "data", directory.resolve())
    text = text.replace('"data/', f'"{data}/')
    return (text + f"""
[[finger]]
fret = {fret}
force = {FINGER['force']}

[[gesture]]
type = "pop"
position = 0.637
width = 0.01
time = {POP_TIME}
release_force = {pull:.6f}
speed = 0.03
""")


def run_names(names):
    return [f"{name}-fret{fret}" for name in names for fret in FRETS[name]]


def write_runs(directory, names):
    directory.mkdir(parents=True, exist_ok=True)
    commands = []
    for name in names:
        path = case_path(name, directory)
        table = stand_in(path, FRETS[name])
        for fret in FRETS[name]:
            run = f"{name}-fret{fret}"
            (directory / f"{run}.toml").write_text(finger_case_text(name, path, fret, table[fret], directory))
            commands.append(f'"$FRETBUZZ" run "$DIR/{run}.toml" --out "$DIR/{run}" -q')
    (directory / "runs.sh").write_text(
        'DIR=$(cd "$(dirname "$0")" && pwd); FRETBUZZ=${FRETBUZZ:-fretbuzz}\n' +
        "".join(f"{c} &\n" for c in commands) + "wait\n")


def run_fingers(directory, names, jobs):
    write_runs(directory, names)
    fretbuzz = binary("cli/fretbuzz")

    def one(run):
        if (directory / run / "observation.csv").exists():
            return
        command = ["nice", fretbuzz, "run", str(directory / f"{run}.toml"), "--out", str(directory / run), "-q"]
        print("$", " ".join(command), flush=True)
        subprocess.run(command, check=True)

    with ThreadPoolExecutor(jobs) as pool:
        list(pool.map(one, run_names(names)))


# ---- the reference ----

def open_modes(path):
    import numpy as np
    out = subprocess.run([binary("cli/fretbuzz"), "modes", str(path)], check=True, text=True, capture_output=True).stdout
    rows = [line.split(",") for line in out.splitlines()[1:]]
    return np.array([float(r[1]) for r in rows]), np.array([float(r[2]) for r in rows])


def tail_compliance(freq, length, points):
    """sum over the modes above the table of phi_j(a) phi_j(b) / omega_j^2 for a, b in points
    (explicitly to 64 N, then the integral on the diagonal), c^2 extrapolated linearly in k^2."""
    import numpy as np
    n = len(freq)
    k = np.arange(1, n + 1) * math.pi / length
    c2 = (2 * math.pi * freq / k) ** 2
    top = slice(n - max(2, n // 8), n)
    slope = max(0.0, np.polyfit(k[top] ** 2, c2[top], 1)[0])
    kt = np.arange(n + 1, 64 * n + 1) * math.pi / length
    c2t = c2[-1] + slope * (kt ** 2 - k[-1] ** 2)
    s = np.sin(np.outer(points, kt))
    tail = (2 / length) * (s / (kt ** 2 * c2t)) @ s.T
    kk = (64 * n + 0.5) * math.pi / length
    a = c2[-1] - slope * k[-1] ** 2
    if slope > 0 and a > 0:
        y = math.sqrt(a / slope) / kk
        g = y * y / 3 - y ** 4 / 5 if y < 1e-3 else 1 - math.atan(y) / y
        return tail + np.eye(len(points)) * g / (math.pi * a * kk)
    return tail + np.eye(len(points)) / (math.pi * kk * (a + slope * kk ** 2))


def reference(freq, sigma, length, density, finger, guesses):
    """The partials (damped frequency in Hz, sigma in 1/s) of the string held at x_k and x_(k-1)
    with the finger on it (see the module's docstring)."""
    import numpy as np
    n = len(freq)
    j = np.arange(1, n + 1)
    dx = length / (n + 1)
    phi = lambda xs: math.sqrt(2 / length) * np.sin(np.outer(xs, j) * math.pi / length)
    holds = [finger["stop"]] + ([finger["behind"]] if finger["behind"] > 0 else [])
    z = phi(holds).T
    w, v = np.linalg.eigh(np.diag((2 * math.pi * freq) ** 2) + z @ np.linalg.solve(tail_compliance(freq, length, holds), z.T))
    w, v = w[:-len(holds)], v[:, :-len(holds)]
    m = len(w)
    pad = pad_points(finger["pad_centre"], finger["pad_width"], dx, n)
    p = len(pad)
    force, stiffness, exponent = FINGER["force"], FINGER["stiffness"], FINGER["exponent"]
    eta = (force / stiffness) ** (1 / exponent)
    spring = exponent * stiffness / p * eta ** (exponent - 1) / density
    damper = FINGER["loss"] * force / p / density
    e = np.zeros((p, m + 1))  # u_i - z at each pad point
    e[:, :m] = phi([(i + 1) * dx for i in pad]) @ v
    e[:, m] = -1.0
    k = spring * e.T @ e
    k[:m, :m] += np.diag(w)
    c = damper * e.T @ e
    c[:m, :m] += v.T @ (2 * sigma[:, None] * v)
    mass = np.ones(m + 1)
    mass[m] = FINGER["mass"] / density
    state = np.zeros((2 * m + 2, 2 * m + 2))
    state[:m + 1, m + 1:] = np.eye(m + 1)
    state[m + 1:, :m + 1] = -k / mass[:, None]
    state[m + 1:, m + 1:] = -c / mass[:, None]
    lam, vec = np.linalg.eig(state)
    keep = lam.imag > 0
    lam, vec = lam[keep], vec[:m, keep]
    grid = dx * j
    shapes = phi(grid) @ (v @ vec)
    energy = np.abs(shapes) ** 2
    far = energy[grid > finger["stop"]].sum(0) / energy.sum(0)
    out, ratio = [], 1.0
    for guess in guesses:
        target = 2 * math.pi * guess * ratio
        distance = np.abs(np.log(np.abs(lam) / target))
        i = int(np.argmin(np.where((far > 0.5) & (distance < 0.03), distance, np.inf)))
        out.append((lam[i].imag / (2 * math.pi), -lam[i].real))
        ratio = abs(lam[i]) / (2 * math.pi * guess)
    return out


# ---- the finger runs' partials ----

def pencil(y, step, guess):
    """Poles of a baseband signal near 0 Hz: (frequency, sigma, energy over the window) of each."""
    import numpy as np
    rows = len(y) // 2
    hankel = np.array([y[i:i + rows + 1] for i in range(len(y) - rows)])
    vh = np.linalg.svd(hankel, full_matrices=False)[2][:16].T
    poles = np.linalg.eigvals(np.linalg.pinv(vh[:-1]) @ vh[1:])
    amplitude = np.abs(np.linalg.lstsq(np.vander(poles, len(y), increasing=True).T, y, rcond=None)[0])
    # Each pole's energy over the window (a fast-decaying pole's large initial amplitude counts less).
    energy = amplitude ** 2 * np.array([np.sum(np.abs(p) ** (2 * np.arange(len(y)))) for p in poles])
    f = guess + np.angle(poles) / (2 * math.pi * step)
    sigma = -np.log(np.abs(poles)) / step
    return [(f[i], sigma[i], energy[i]) for i in range(len(poles)) if f[i] > 0 and abs(cents(f[i], guess)) < 30]


def finger_partials(observation, guesses):
    """(frequency, sigma) of each partial from u(t) at the observation point (see the docstring)."""
    import numpy as np
    import scipy.signal as ss
    data = np.loadtxt(observation, delimiter=",", skiprows=1, usecols=(0, 1))
    t, dt = data[:, 0], data[1, 0] - data[0, 0]
    u = data[:, 1] - data[t >= START, 1].mean()
    out = []
    for guess in guesses:
        y = u * np.exp(-2j * math.pi * guess * dt * np.arange(len(u)))
        y = ss.decimate(ss.decimate(y, 10, ftype="fir", zero_phase=True), 10, ftype="fir", zero_phase=True)
        step = 100 * dt
        tt = t[0] + step * np.arange(len(y))
        span = 0.85
        for _ in range(3):  # a window 3 / sigma long, as the partial lasts
            window = (tt >= START) & (tt <= START + span)
            f, sigma, _ = max(pencil(y[window], step, guess), key=lambda p: p[2])
            span = min(0.85, max(0.08, 3.0 / sigma))
        out.append((f, sigma))
    return out


def cents(a, b):
    return 1200 * math.log2(a / b)


def analyse(runs, names):
    summary = {}
    for name in names:
        path = case_path(name, runs)
        freq, sigma = open_modes(path)
        fb = fretbuzz_module()
        case = fb.load_case(str(path))
        table = stand_in(path, FRETS[name])
        print(f"\n**{name}** (reference: Hz and 1/s; the others: cents from it, and their damping over its)\n")
        print("| fret | x_k (m) | | " + " | ".join(str(n) for n in range(1, PARTIALS + 1)) + " |")
        print("|---|---|---|" + "---|" * PARTIALS)
        for fret in FRETS[name]:
            finger = table[fret]
            ref = reference(freq, sigma, case.L, case.mu, finger, finger["pinned"])
            # The stand-in's table holds the natural frequency |s|: its oscillation, sqrt(|s|^2 - sigma^2).
            held = [(math.sqrt(f * f - (s / (2 * math.pi)) ** 2), s) for f, s in zip(finger["held"], finger["sigma"])]
            rows = [("reference (Hz)", [f"{f:.2f}" for f, _ in ref]),
                    ("reference sigma (1/s)", [f"{s:.2f}" for _, s in ref]),
                    ("pinned, B' (cents)", [f"{cents(a, b[0]):+.2f}" for a, b in zip(finger["pinned"], ref)]),
                    ("stand-in (cents)", [f"{cents(a[0], b[0]):+.2f}" for a, b in zip(held, ref)]),
                    ("stand-in sigma / reference", [f"{a[1] / b[1]:.2f}" for a, b in zip(held, ref)])]
            models = {"stand-in": held}
            observation = runs / f"{name}-fret{fret}" / "observation.csv"
            if observation.exists():
                measured = finger_partials(observation, [f for f, _ in held])
                models["finger"] = measured
                rows += [("finger (cents)", [f"{cents(a[0], b[0]):+.2f}" for a, b in zip(measured, ref)]),
                         ("finger sigma / reference", [f"{a[1] / b[1]:.2f}" for a, b in zip(measured, ref)])]
            for model, values in models.items():
                entry = summary.setdefault((name, model), [[], []])
                entry[0] += [cents(a[0], b[0]) for a, b in zip(values, ref)]
                entry[1] += [a[1] / b[1] for a, b in zip(values, ref)]
            for label, cells in rows:
                first = label.startswith("reference (Hz)")
                where = f"{fret} | {finger['stop']:.3f}" if first else " | "
                print(f"| {where} | {label} | " + " | ".join(cells) + " |")
    print()
    for (name, model), (pitch, damping) in summary.items():
        print(f"{name}, {model}: {min(pitch):+.3f} to {max(pitch):+.3f} cents from the reference, its damping "
              f"{min(damping):.3f} to {max(damping):.3f} times the reference's (partials 1-{PARTIALS}, frets "
              f"{', '.join(map(str, FRETS[name]))})")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--jobs", type=int, default=2, help="finger runs at a time")
    parser.add_argument("--cases", default=",".join(FRETS), help=f"comma-separated, of {', '.join(FRETS)}")
    parser.add_argument("--runs", type=Path, help="read the finger runs from this directory")
    parser.add_argument("--write-runs", type=Path, help="write the finger runs' case files and runs.sh here and stop")
    a = parser.parse_args()
    names = a.cases.split(",")
    for name in names:
        if name not in FRETS:
            parser.error(f"--cases: {name!r} is not one of {', '.join(FRETS)}")
    if a.write_runs:
        write_runs(a.write_runs, names)
        print(f"written: {a.write_runs}/runs.sh (FRETBUZZ=/path/to/fretbuzz sh {a.write_runs}/runs.sh)")
        return
    runs = a.runs
    if runs is None:
        runs = ROOT / "build" / "stopped-note-runs"
        run_fingers(runs, names, a.jobs)
    analyse(runs, names)
    print(f"run time: {time.perf_counter() - STARTED:.0f} s")


STARTED = time.perf_counter()

if __name__ == "__main__":
    main()
