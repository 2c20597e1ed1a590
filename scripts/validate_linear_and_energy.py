#!/usr/bin/python3
"""Exactness of the linear part (no obstacle: the signal does not depend on Fe) and the
discrete energy of bass-pop: conserved to round-off without losses, balanced with them."""
import json

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from validation_common import case_variant, fretbuzz, read_csv, savefig, scratch_dir

out = scratch_dir("energy")
free = case_variant("bass-pop", out, obstacle_none=True)

# 1. Linear part: 96 kHz (below the highest mode's 2x frequency: aliased steps) against 4 MHz.
signals = {}
for fs in (96000, 4000000):
    fretbuzz("run", free, "--fs", fs, "--duration", 0.05, "--output-rate", 32000, "--out", out / f"free{fs}", "-q")
    signals[fs] = read_csv(out / f"free{fs}" / "observation.csv")[1][:, 1]
a, b = signals[96000], signals[4000000]
print(f"linear part: relative L2 difference 96 kHz vs 4 MHz over 0.05 s = {np.linalg.norm(a - b) / np.linalg.norm(b):.2e}")

# 2. Energy with contact, lossless and damped, at the paper's Fe = 4 MHz.
runs = {}
for label, extra in (("lossless", ["--lossless"]), ("damped", [])):
    fretbuzz("run", "bass-pop", "--duration", 0.1, *extra, "--out", out / label, "-q")
    header, energy = read_csv(out / label / "energy.csv")
    summary = json.loads((out / label / "summary.json").read_text())
    runs[label] = (energy, summary)
    h0 = summary["energy_initial_J"]
    balance = energy[:, 1] + energy[:, 3] - h0
    print(f"{label}: H^1/2 = {h0:.6e} J, contact steps = {summary['contact_steps']}, "
          f"max |H + dissipated - H0| / H0 = {np.max(np.abs(balance)) / h0:.2e} (48 kHz rows), "
          f"run summary (every output step): balance {summary['max_relative_energy_balance_error']:.2e}, "
          f"max increase {summary['max_relative_energy_increase']:.2e}, wall {summary['wall_seconds']:.1f} s")

fig, (a, b) = plt.subplots(1, 2, figsize=(10, 3.6))
for label, (energy, summary) in runs.items():
    h0 = summary["energy_initial_J"]
    a.plot(energy[:, 0] * 1e3, energy[:, 1] * 1e3, label=f"H, {label}")
    b.semilogy(energy[:, 0] * 1e3, np.abs(energy[:, 1] + energy[:, 3] - h0) / h0 + 1e-18, lw=0.8,
               label=f"|H + dissipated - H(0)| / H(0), {label}")
energy = runs["damped"][0]
a.plot(energy[:, 0] * 1e3, (energy[:, 1] + energy[:, 3]) * 1e3, "k:", label="H + dissipated, damped")
a.set_xlabel("t [ms]"), a.set_ylabel("energy [mJ]"), a.legend(fontsize=7)
b.set_xlabel("t [ms]"), b.set_ylabel("relative error"), b.legend(fontsize=7), b.set_ylim(1e-17, 1e-10)
fig.tight_layout()
savefig(fig, "energy_balance.png")
