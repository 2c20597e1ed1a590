#!/usr/bin/python3
"""The paper's observations on bass-pop, quantified: which frets are hit and when, the
step-wise energy decay during the contacts, the formant near 4.5 kHz, the downward pitch
glide of the low modes, and the sensitivity to the fret height (+-0.1 mm)."""
import json

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from validation_common import case_variant, fret_points, fretbuzz, read_csv, savefig, scratch_dir

DURATION, RATE, SENSITIVITY_DURATION = 0.4, 100000, 0.2
out = scratch_dir("observations")
table, frets = fret_points()
fret_x, fret_g = table[frets, 0], table[frets, 1]
observe = [a for x in fret_x for a in ("--observe", f"{x:.3f}")]


def simulate(case, label, duration, fs=4000000):
    fretbuzz("run", case, "--fs", fs, "--duration", duration, "--output-rate", RATE, *observe, "--out", out / label, "-q")
    _, u = read_csv(out / label / "observation.csv")
    _, energy = read_csv(out / label / "energy.csv")
    return u, energy, json.loads((out / label / "summary.json").read_text())


def fret_contacts(u, heights=fret_g):
    """Boolean matrix (sample, fret): the string is below the fret top (penetration)."""
    return u[:, 2:] < heights[None, :]


def episodes(flags):
    starts = np.flatnonzero(np.diff(np.concatenate(([0], flags.astype(int)))) == 1)
    return len(starts)


u, energy, summary = simulate("bass-pop", "nominal", DURATION)
free_case = case_variant("bass-pop", out / "free", obstacle_none=True)
# Without an obstacle the scheme is exact at any Fe: 200 kHz gives the 4 MHz signal.
u_free, energy_free, _ = simulate(free_case, "free", DURATION, fs=200000)
t = u[:, 0]

# 1. Which frets are hit and when.
contact = fret_contacts(u)
print(f"first contact {summary['first_contact_s'] * 1e3:.2f} ms, last contact {summary['last_contact_s'] * 1e3:.2f} ms, "
      f"{summary['contact_steps']} steps with contact (of {summary['steps']})")
print("fret  x [m]   samples in contact  episodes  first [ms]  last [ms]")
hit = []
for k, x in enumerate(fret_x):
    column = contact[:, k]
    if column.any():
        hit.append(k + 1)
        times = t[column]
        print(f"{k + 1:4d}  {x:.3f}  {column.sum():18d}  {episodes(column):8d}  {times[0] * 1e3:10.2f}  {times[-1] * 1e3:9.2f}")
print(f"frets hit: {hit} ({len(hit)} of {len(fret_x)}); contact seen at {RATE / 1e3:.0f} kHz output samples")

# 2. Step-wise energy decay: energy lost while some fret is in contact vs in between.
in_contact = energy[:, 2] > 0.0
dh = np.diff(energy[:, 1])
window = energy[:, 0] <= summary["last_contact_s"]
lost_contact = -dh[in_contact[1:] & window[1:]].sum()
lost_free = -dh[~in_contact[1:] & window[1:]].sum()
h0 = energy[0, 1]
print(f"energy until the last contact: {lost_contact / h0:.1%} of H(0) lost during contact samples "
      f"({in_contact[window].mean():.1%} of the time), {lost_free / h0:.1%} in between; "
      f"without the obstacle {1 - energy_free[np.searchsorted(energy_free[:, 0], summary['last_contact_s']), 1] / h0:.1%}")

# 3. Formant: spectra of the first 0.1 s with and without the obstacle.
def spectrum(signal, rate, duration=0.1):
    n = int(duration * rate)
    x = signal[:n] * np.hanning(n)
    return np.fft.rfftfreq(8 * n, 1 / rate), np.abs(np.fft.rfft(x, 8 * n))


f, s_contact = spectrum(u[:, 1], RATE)
_, s_free = spectrum(u_free[:, 1], RATE)
def smooth(x, bins=400):
    return np.convolve(x ** 2, np.ones(bins) / bins, mode="same")
gain_db = 10 * np.log10(smooth(s_contact) / smooth(s_free))
envelope_db = 10 * np.log10(smooth(s_contact))
band = (f > 3000) & (f < 7000)
peak = f[band][np.argmax(envelope_db[band])]
level = lambda hz: np.interp(hz, f, envelope_db)
print(f"formant: smoothed ({400 * (f[1] - f[0]):.0f} Hz) spectrum of the contact run peaks in 3-7 kHz at {peak:.0f} Hz: "
      f"{level(peak) - level(3000):+.1f} dB over 3 kHz, {level(peak) - level(7000):+.1f} dB over 7 kHz; "
      f"gain over the free run: {np.interp(2000, f, gain_db):.1f} dB at 2 kHz, {np.interp(peak, f, gain_db):.1f} dB at the peak")

# 4. Pitch glide: the fundamental's frequency in 40 ms frames (peak of a zero-padded spectrum).
def fundamental_track(signal, rate, frame=0.04, hop=0.005, near=98.0):
    n, step = int(frame * rate), int(hop * rate)
    times, freqs = [], []
    for start in range(0, len(signal) - n, step):
        x = signal[start:start + n] * np.hanning(n)
        spec = np.abs(np.fft.rfft(x - x.mean(), 64 * n))
        ff = np.fft.rfftfreq(64 * n, 1 / rate)
        sel = (ff > 0.6 * near) & (ff < 1.4 * near)
        times.append((start + n / 2) / rate)
        freqs.append(ff[sel][np.argmax(spec[sel])])
    return np.array(times), np.array(freqs)


tc, fc = fundamental_track(u[:, 1], RATE)
tf, ff = fundamental_track(u_free[:, 1], RATE)
print(f"fundamental: free string {ff.mean():.2f} Hz; with frets {fc[0]:.2f} Hz at {tc[0] * 1e3:.0f} ms -> "
      f"{fc[-1]:.2f} Hz at {tc[-1] * 1e3:.0f} ms (glide {fc[0] - fc[-1]:.2f} Hz, {1200 * np.log2(fc[0] / fc[-1]):.0f} cents)")

# 5. Fret height +-0.1 mm.
variants = {}
for delta in (+1e-4, -1e-4):
    modified = table.copy()
    modified[frets, 1] += delta
    name = f"frets{'+' if delta > 0 else '-'}0.1mm"
    np.savetxt(out / f"{name}.csv", modified, delimiter=",", header="x_m,height_m", comments="# ", fmt="%.17g")
    case = case_variant("bass-pop", out / name, obstacle_csv=f"../{name}.csv")
    uu, ee, ss = simulate(case, name, SENSITIVITY_DURATION)
    variants[name] = (uu, ee, ss, fret_g + delta)
n = len(variants["frets+0.1mm"][0])
reference = u[:n, 1]
print("fret heights   rel. L2 diff of u(0.854) over 0.2 s   contact steps   frets hit   H(0.2 s)/H(0)")
for name, (uu, ee, ss, heights) in [("nominal", (u[:n], energy, summary, fret_g))] + list(variants.items()):
    frets_hit = np.flatnonzero(fret_contacts(uu[:n], heights).any(axis=0)) + 1
    h_end = ee[np.searchsorted(ee[:, 0], SENSITIVITY_DURATION) - 1, 1] / ee[0, 1]
    diff = np.linalg.norm(uu[:n, 1] - reference) / np.linalg.norm(reference)
    steps = ss["contact_steps"] if name != "nominal" else "-"
    print(f"{name:13s}  {diff:34.3f}   {steps!s:>13}   {len(frets_hit):9d}   {h_end:13.3f}")

# Figures.
fig, axes = plt.subplots(3, 1, figsize=(8, 7.5), sharex=True)
axes[0].plot(t * 1e3, u[:, 1] * 1e3, lw=0.6, label="with frets")
axes[0].plot(u_free[:, 0] * 1e3, u_free[:, 1] * 1e3, lw=0.6, alpha=0.6, label="no obstacle")
axes[0].set_ylabel("u(0.854 m) [mm]"), axes[0].legend(fontsize=7)
rows, cols = np.nonzero(contact)
axes[1].plot(t[rows] * 1e3, fret_x[cols], "|", ms=4)
axes[1].set_ylabel("fret x [m]")
axes[2].plot(energy[:, 0] * 1e3, energy[:, 1] / h0, label="with frets")
axes[2].plot(energy_free[:, 0] * 1e3, energy_free[:, 1] / h0, label="no obstacle")
axes[2].set_ylabel("H / H(0)"), axes[2].set_xlabel("t [ms]"), axes[2].legend(fontsize=7)
for ax in axes:
    ax.set_xlim(0, 1e3 * summary["last_contact_s"] * 1.3)
fig.tight_layout()
savefig(fig, "bass_pop_contacts.png")

fig, (a, b) = plt.subplots(1, 2, figsize=(10, 3.6))
a.semilogy(f / 1e3, s_contact, lw=0.4, label="with frets")
a.semilogy(f / 1e3, s_free, lw=0.4, alpha=0.7, label="no obstacle")
a.semilogy(f / 1e3, np.sqrt(smooth(s_contact)), "k", lw=1, label="with frets, smoothed")
a.axvline(peak / 1e3, color="k", ls=":", lw=0.8)
a.set_xlim(0, 10), a.set_xlabel("f [kHz]"), a.set_ylabel("|U(f)|, first 0.1 s"), a.legend(fontsize=7)
b.plot(f / 1e3, gain_db), b.axvline(peak / 1e3, color="k", ls=":", lw=0.8)
b.set_xlim(0, 9), b.set_ylim(-10, 40), b.set_xlabel("f [kHz]"), b.set_ylabel("gain over the free string [dB]")
fig.tight_layout()
savefig(fig, "bass_pop_formant.png")

fig, (a, b) = plt.subplots(1, 2, figsize=(10, 3.4))
a.plot(tc * 1e3, fc, label="with frets"), a.plot(tf * 1e3, ff, label="no obstacle")
a.set_xlabel("t [ms] (frame centre, 40 ms frames)"), a.set_ylabel("fundamental [Hz]"), a.legend(fontsize=7)
for name, (uu, ee, ss, _) in variants.items():
    b.plot(uu[:, 0] * 1e3, uu[:, 1] * 1e3, lw=0.5, label=name)
b.plot(t[:n] * 1e3, reference * 1e3, "k", lw=0.5, label="nominal")
b.set_xlim(0, 30), b.set_xlabel("t [ms]"), b.set_ylabel("u(0.854 m) [mm]"), b.legend(fontsize=7)
fig.tight_layout()
savefig(fig, "bass_pop_glide_and_fret_height.png")
