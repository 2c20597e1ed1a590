#!/usr/bin/python3
"""Why the aliasing rule (include/fretbuzz/scheme/SamplingCheck.hpp, docs/validation.md):
an ideal lossless string (L = 1 m, T = 200 N, mu = 1e-3 kg/m, f1 = 223.6 Hz) plucked up
2 mm at 0.3 m against a hard flat barrier 1 mm below it (K = 1e12, alpha = 1.5), observed
at 0.7 m for 50 ms. At fs = 176.4 kHz it is run with more and more modes (aliasing
allowed) and compared (relative L2 error of the displacement, over the first 10 ms and
over 50 ms) with the same modes at 8 x 176.4 kHz, where every one of them is below fs/2:
the error the sampling rate causes.

Run: /usr/bin/python3 scripts/aliasing_flat_barrier.py   (after building fretbuzz)
"""
import math

import numpy as np

from validation_common import fretbuzz, read_csv, scratch_dir

FS = 176400.0
F1 = 100.0 * math.sqrt(5.0)


def case_text(modes, fs):
    return f"""name = "flat-barrier"
[string]
L = 1.0
T = 200.0
mu = 1e-3
modes = {modes}
ideal = true
[obstacle]
type = "flat"
height = -1e-3
[excitation]
type = "triangle"
position = 0.3
amplitude = 2e-3
[contact]
K = 1e12
alpha = 1.5
[run]
fs = {fs}
duration = 0.05
output_rate = {FS}
lossless = true
allow_aliasing = true
[observe]
x = [0.7]
"""


def displacement(work, modes, fs):
    directory = work / f"m{modes}-fs{int(fs)}"
    directory.mkdir()
    path = directory / "case.toml"
    path.write_text(case_text(modes, fs))
    fretbuzz("run", path, "-q", "--out", directory / "out")
    return read_csv(directory / "out" / "observation.csv")[1][:, 1]


def main():
    work = scratch_dir("aliasing")
    def error(u, reference, seconds):
        n = min(u.size, reference.size, int(round(seconds * FS)) + 1)
        return np.linalg.norm(u[:n] - reference[:n]) / np.linalg.norm(reference[:n])

    rows = []
    for modes in (394, 700, 788, 789, 800, 1000, 1576):
        u = displacement(work, modes, FS)
        reference = displacement(work, modes, 8 * FS)
        above = sum(1 for j in range(1, modes + 1) if j * F1 > FS / 2)
        alias = min(abs(j * F1 - round(j * F1 / FS) * FS) for j in range(1, modes + 1))
        rows.append(f"| {modes} | {above} | {alias:.1f} | {100 * error(u, reference, 0.01):.1f} % | "
                    f"{100 * error(u, reference, 0.05):.1f} % |")
    print("\n| modes | modes above fs/2 | nearest alias (Hz) | error over 10 ms | error over 50 ms |")
    print("|---|---|---|---|---|")
    print("\n".join(rows))


if __name__ == "__main__":
    main()
