#!/usr/bin/python3
"""The modal scheme against the independent finite-difference scheme (Bilbao, Torin and
Chatziioannou 2015) on a lossless ideal string slapping a flat obstacle: table and figure."""
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from validation_common import fretbuzz, read_csv, savefig, scratch_dir

out = scratch_dir("cross-check")
print(fretbuzz("cross-check", "--N", "80,160,320,640,1280", "--out", out, capture=True))
_, levels = read_csv(out / "cross_check.csv")
header, signals = read_csv(out / "cross_check_signals.csv")

fig, (a, b) = plt.subplots(1, 2, figsize=(10, 3.8))
t = signals[:, 0]
a.plot(t, signals[:, 1], "k", lw=2, label="modal, 1279 modes, 6400 Hz")
for k, name in enumerate(header[2:], start=2):
    if name in ("fd_N80", "fd_N320"):
        a.plot(t, signals[:, k], "--", lw=1, label=f"finite differences, N = {name[4:]}")
a.axhline(-0.02, color="tab:brown", lw=0.8, label="obstacle")
a.set_xlabel("t"), a.set_ylabel("u(0.25, t)"), a.legend(fontsize=7), a.set_title("signals (dimensionless)", fontsize=9)
n = levels[:, 0]
b.loglog(n, levels[:, 2], "o-", label="FD vs reference")
b.loglog(n, levels[:, 3], "s-", label="modal (same grid, same dt) vs reference")
b.loglog(n, levels[:, 4], "^-", label="FD vs modal (same grid, same dt)")
b.loglog(n, levels[:, 2][0] * (n / n[0]) ** -2.0, "k:", lw=0.8, label="slope -2")
b.set_xlabel("N (grid intervals; dt = 0.8 h / c)"), b.set_ylabel("relative L2 difference over 2 s")
b.legend(fontsize=7), b.grid(True, which="both", alpha=0.3)
fig.tight_layout()
savefig(fig, "cross_check.png")
