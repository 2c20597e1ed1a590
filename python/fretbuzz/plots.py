#!/usr/bin/python3
"""Figures of one fretbuzz run, drawn from the results.h5 in its output directory.

Usage: python3 -m fretbuzz.plots DIR (or `fretbuzz plot DIR`) [--animation gif|mp4|none] [--quiet]
       [--format png|pdf|svg ...] [--zoom START:END ...] [--db-range DB] [--max-frequency HZ]

Writes into DIR:
  signal.png             displacement at the first observation point, zoomed windows, energy
                         (the layout of Figure 2 in Issanchou et al. 2017)
  signal_all_points.png  every observation point (only when there are several)
  spectrogram.png        0-10 kHz spectrogram of the first observation point (Figure 3)
  spectrogram_y.png      the same for the y polarisation        (two polarisations)
  orbit.png              y against z at the first observation point over the zoomed
                         windows (two polarisations)
  energy.png             energy, contact energy, dissipated energy and the balance error
  contactogram.png       x against t, coloured by the contact force (fingers' and gestures' pads marked)
  snapshots.png          string shapes over the obstacle, with the fingers and pluckers (when the run stored snapshots)
  animation.gif / .mp4   the string moving over the obstacle (when the run stored snapshots)
or, for a run of strings on a bridge (strings.csv, no results.h5):
  strings_energy.png     each string's energy and the bridge's over time, and the balance

`fretbuzz plot DIR` runs this script with Debian's /usr/bin/python3 (numpy, matplotlib, h5py).
"""
import argparse
import json
import math
import os
import shutil
import sys

ZOOM_WINDOWS = 3
MAX_CONTACTOGRAM_COLUMNS = 700  # about one pixel per column, so short contacts stay visible
MAX_ANIMATION_FRAMES = 100
ANIMATION_DPI = 128  # 8 x 3 inches: 1024 x 384 pixels
SNAPSHOT_PANELS = 6
# The spectrogram's colours span this many dB below its peak, up to this frequency: 60 dB
# shows a decaying string's partials without turning the picture black.
DB_RANGE = 60.0
MAX_FREQUENCY = 10000.0


def parse_arguments(argv):
    parser = argparse.ArgumentParser(description="Figures of a fretbuzz run")
    parser.add_argument("dir", help="output directory of `fretbuzz run` (holding results.h5)")
    parser.add_argument("--animation", choices=["gif", "mp4", "none"], default="gif")
    parser.add_argument("--quiet", action="store_true")
    parser.add_argument("--format", dest="formats", action="append", choices=["png", "pdf", "svg"],
                        help="file format of the figures (repeatable; default png)")
    parser.add_argument("--zoom", dest="zoom", action="append", type=zoom_window,
                        help="a zoomed window START:END in s of signal.png (repeatable)")
    parser.add_argument("--db-range", type=float, default=DB_RANGE, help="spectrogram colour range in dB")
    parser.add_argument("--max-frequency", type=float, default=MAX_FREQUENCY, help="spectrogram top frequency (Hz)")
    return parser.parse_args(argv)


def zoom_window(text):
    start, end = (float(v) for v in text.split(":"))
    if not 0 <= start < end:
        raise ValueError(f"zoom window {text}: need 0 <= START < END")
    return start, end


class Results:
    """The arrays of results.h5 that the figures need, in SI units."""

    def __init__(self, path, h5py, np):
        with h5py.File(path, "r") as f:
            self.case = str(f.attrs.get("case", ""))
            self.length = float(f.attrs["length_m"])
            self.time = f["time"][()]
            self.points = f["observation/points_m"][()]
            self.displacement = f["observation/displacement"][()]
            # Two polarisations: y (parallel to the fretboard) at the same points.
            self.displacement_y = f["observation/displacement_y"][()] if "observation/displacement_y" in f else None
            self.energy_time = f["energy/time"][()]
            self.energy = f["energy/total"][()]
            self.contact_energy = f["energy/contact"][()]
            self.dissipated = f["energy/dissipated"][()]
            self.grid_x = f["grid/x_m"][()]
            self.obstacle = f["grid/obstacle_height_m"][()]
            self.map_time, self.map_force = reduced_contact_map(f, np, MAX_CONTACTOGRAM_COLUMNS)
            self.snapshot_time = f["snapshots/time"][()] if "snapshots" in f else np.empty(0)
            self.snapshots = f["snapshots/displacement"][()] if "snapshots" in f else np.empty((0, 0))
            self.summary = json.loads(f["summary"][()]) if "summary" in f else {}
            # Fingers and gestures (only in runs that have them): kind, pad, height over time.
            played = "played" in f
            self.played_kind = [k.decode() if isinstance(k, bytes) else str(k) for k in f["played/kind"][()]] \
                if played else []
            self.played_position = f["played/position_m"][()] if played else np.empty(0)
            self.played_width = f["played/width_m"][()] if played else np.empty(0)
            self.played_height = f["played/height"][()] if played else np.empty((0, 0))
            self.work = f["energy/work"][()] if played else None
            self.finger_energy = f["energy/finger"][()] if played else None


def contact_map_times(f, np):
    """End time of every row of the contact map: row r ends at step min((r+1) interval, steps)."""
    contact = f["contact"]
    interval, rows = int(contact.attrs["interval_steps"]), int(contact.attrs["rows"])
    end_steps = np.minimum((np.arange(rows, dtype=np.int64) + 1) * interval, int(f.attrs["steps"]))
    return end_steps.astype(np.float64) * float(f.attrs["dt_s"])


def reduced_contact_map(f, np, max_rows=None):
    """The contact map as a dense float32 array (rows x grid points) rebuilt from its sparse
    entries, with the row times. With max_rows, groups of consecutive rows are folded by
    their maximum so that at most max_rows remain (time: the end of each group)."""
    time = contact_map_times(f, np)
    rows, points = len(time), len(f["grid/x_m"])
    group = 1 if max_rows is None else max(1, math.ceil(rows / max_rows))
    entry_rows = f["contact/row"][()] // group
    dense = np.zeros((math.ceil(rows / group), points), dtype=np.float32)
    np.maximum.at(dense, (entry_rows, f["contact/point"][()]), f["contact/max_force"][()])
    if group > 1:
        time = np.append(time[group - 1::group], time[-1]) if rows % group else time[group - 1::group]
    return time, dense


# The file formats each figure is saved in (plot_directory's `formats`); PDF and SVG are
# vector formats for papers. OPTIONS: plot_directory's zoom windows and spectrogram range.
FORMATS = ["png"]
OPTIONS = {"zoom": None, "db_range": DB_RANGE, "max_frequency": MAX_FREQUENCY}


def save(fig, directory, name, written, description=None):
    """Saves fig as name in every format asked for; description (text) goes into a PNG's metadata."""
    stem = os.path.splitext(name)[0]
    for form in FORMATS:
        path = os.path.join(directory, f"{stem}.{form}")
        fig.savefig(path, dpi=110, metadata={"Description": description} if description and form == "png" else None)
        written.append(path)


def zoom_windows(duration, first_contact):
    """Start times of the zoomed windows: the first contacts, the middle, the end."""
    width = duration / 25.0
    starts = [max(0.0, first_contact if first_contact >= 0 else 0.02 * duration), 0.45 * duration, 0.9 * duration]
    return [(min(s, duration - width), min(s, duration - width) + width) for s in starts[:ZOOM_WINDOWS]]


def plot_signal(r, plt, np, directory, written):
    t, u = r.time, r.displacement[:, 0] * 1e3
    fig = plt.figure(figsize=(10, 7.5), layout="constrained")
    duration = t[-1] if len(t) else 0.0
    windows = OPTIONS["zoom"] or zoom_windows(duration, float(r.summary.get("first_contact_s", -1.0)))
    grid = fig.add_gridspec(3, len(windows), height_ratios=[1.2, 1, 1])
    top = fig.add_subplot(grid[0, :])
    top.plot(t, u, lw=0.6, color="C0")
    top.set_ylabel("u (mm)")
    top.set_title(f"{r.case}: displacement at x = {r.points[0]:g} m")
    for k, (a, b) in enumerate(windows):
        letter = "abcdefghijklmnopqrstuvwxyz"[k % 26]
        top.axvspan(a, b, color="C1", alpha=0.25)
        top.annotate(f"({letter})", (0.5 * (a + b), 0.98), xycoords=("data", "axes fraction"), ha="center", va="top")
        zoom = fig.add_subplot(grid[1, k])
        inside = (t >= a) & (t <= b)
        zoom.plot(t[inside] * 1e3, u[inside], lw=0.8, color="C0")
        zoom.set_title(f"({letter}) {a * 1e3:.1f}-{b * 1e3:.1f} ms", fontsize=9)
        zoom.set_xlabel("t (ms)")
        if k == 0:
            zoom.set_ylabel("u (mm)")
    top.set_xlim(0, duration)
    bottom = fig.add_subplot(grid[2, :], sharex=top)
    bottom.plot(r.energy_time, r.energy, color="C2", lw=1.0)
    bottom.set_ylabel("energy H (J)")
    bottom.set_xlabel("t (s)")
    save(fig, directory, "signal.png", written)
    plt.close(fig)


def plot_all_points(r, plt, directory, written):
    count = len(r.points)
    fig, axes = plt.subplots(count, 1, figsize=(10, 1.8 * count + 1), sharex=True, layout="constrained", squeeze=False)
    for p, ax in enumerate(axes[:, 0]):
        ax.plot(r.time, r.displacement[:, p] * 1e3, lw=0.6, color=f"C{p % 10}")
        ax.set_ylabel(f"u (mm)\nx = {r.points[p]:g} m")
    axes[-1, 0].set_xlabel("t (s)")
    save(fig, directory, "signal_all_points.png", written)
    plt.close(fig)


def plot_spectrogram(r, plt, np, directory, written, polarisation="z"):
    t = r.time
    u = r.displacement_y[:, 0] if polarisation == "y" else r.displacement[:, 0]
    rate = 1.0 / (t[1] - t[0]) if len(t) > 1 else 1.0
    nfft = 2 ** round(math.log2(max(64.0, 0.04 * rate)))  # about 40 ms windows
    while nfft > 64 and nfft > len(u) // 4:
        nfft //= 2
    fig, ax = plt.subplots(figsize=(10, 5), layout="constrained")
    if len(u) < 2 * nfft:
        ax.text(0.5, 0.5, "run too short for a spectrogram", ha="center", transform=ax.transAxes)
    else:
        with np.errstate(divide="ignore"):  # silent bins are -inf dB, clipped by the colour limits
            spectrum, frequencies, times, image = ax.specgram(
                u - np.mean(u), NFFT=nfft, Fs=rate, noverlap=nfft * 7 // 8, window=np.hanning(nfft),
                scale="dB", mode="psd", cmap="magma")
        # u in m: the density is in m^2/Hz, so its dB are re 1 m^2/Hz.
        db = 10 * np.log10(np.maximum(spectrum, 1e-300))
        top = db[frequencies <= OPTIONS["max_frequency"]].max()
        image.set_clim(top - OPTIONS["db_range"], top)
        fig.colorbar(image, ax=ax, label="power spectral density (dB re 1 m$^2$/Hz)")
    ax.set_ylim(0, min(OPTIONS["max_frequency"], rate / 2))
    ax.set_xlabel("t (s)")
    ax.set_ylabel("frequency (Hz)")
    along = " (y, along the fretboard)" if polarisation == "y" else (" (z)" if r.displacement_y is not None else "")
    ax.set_title(f"{r.case}: spectrogram at x = {r.points[0]:g} m{along}")
    save(fig, directory, "spectrogram_y.png" if polarisation == "y" else "spectrogram.png", written)
    plt.close(fig)


def plot_orbit(r, plt, np, directory, written):
    """y against z at the first observation point: the whole run faint, each zoomed window on top."""
    t, z, y = r.time, r.displacement[:, 0] * 1e3, r.displacement_y[:, 0] * 1e3
    duration = t[-1] if len(t) else 0.0
    windows = OPTIONS["zoom"] or zoom_windows(duration, float(r.summary.get("first_contact_s", -1.0)))
    fig, axes = plt.subplots(1, len(windows), figsize=(4 * len(windows), 4.4), layout="constrained", squeeze=False)
    reach = max(np.abs(z).max(), np.abs(y).max(), 1e-12) * 1.05 if len(t) else 1.0
    for k, (a, b) in enumerate(windows):
        ax = axes[0, k]
        inside = (t >= a) & (t <= b)
        ax.plot(z, y, lw=0.3, color="0.8")
        ax.plot(z[inside], y[inside], lw=0.8, color=f"C{k}")
        ax.set_xlim(-reach, reach)
        ax.set_ylim(-reach, reach)
        ax.set_aspect("equal")
        ax.set_title(f"{a * 1e3:.1f}-{b * 1e3:.1f} ms", fontsize=9)
        ax.set_xlabel("z, across the fretboard (mm)")
        if k == 0:
            ax.set_ylabel("y, along the fretboard (mm)")
    fig.suptitle(f"{r.case}: orbit at x = {r.points[0]:g} m")
    save(fig, directory, "orbit.png", written)
    plt.close(fig)


def plot_energy(r, plt, np, directory, written):
    fig, (ax, err) = plt.subplots(2, 1, figsize=(10, 6.5), sharex=True, layout="constrained",
                                  gridspec_kw={"height_ratios": [2, 1]})
    # With fingers or gestures the balance is H - W + D (W: the work they did on the string).
    work = r.work if r.work is not None and len(r.work) == len(r.energy) else np.zeros_like(r.energy)
    ax.plot(r.energy_time, r.energy, label="energy H", color="C2")
    ax.plot(r.energy_time, r.dissipated, label="dissipated so far", color="C3")
    if r.work is not None:
        ax.plot(r.energy_time, work, label="work W of fingers and gestures", color="C4")
        ax.plot(r.energy_time, r.finger_energy[:len(r.energy)], label="fingers' energy", color="C5", lw=0.8)
    ax.plot(r.energy_time, r.energy - work + r.dissipated, label="H - W + dissipated" if r.work is not None
            else "H + dissipated", color="k", ls="--", lw=0.8)
    ax.plot(r.energy_time, r.contact_energy, label="contact energy", color="C1")
    ax.set_ylabel("energy (J)")
    ax.legend(loc="center right")
    ax.set_title(f"{r.case}: energy balance")
    if len(r.energy):
        # The first energy row is one output interval in; the balance refers to H^{1/2}.
        initial = float(r.summary.get("energy_initial_J", r.energy[0] + r.dissipated[0]))
        # A string set going from rest is judged against the largest work done.
        scale = max(initial, float(np.abs(work).max()) if len(work) else 0.0)
        balance = np.abs(r.energy - work + r.dissipated - initial) / (scale if scale > 0 else 1.0)
        err.semilogy(r.energy_time, np.maximum(balance, 1e-18), color="k", lw=0.8)
    err.set_ylabel("|H - W + D - H(1/2)| / max(H(1/2), |W|)" if r.work is not None else "|H + D - H(1/2)| / H(1/2)")
    err.set_xlabel("t (s)")
    save(fig, directory, "energy.png", written)
    plt.close(fig)


def plot_contactogram(r, plt, np, directory, written):
    from matplotlib.colors import LogNorm

    fig, ax = plt.subplots(figsize=(10, 5), layout="constrained")
    rows, points = np.nonzero(r.map_force > 0.0)
    if len(rows) == 0:
        ax.text(0.5, 0.5, "no contact", ha="center", transform=ax.transAxes)
        ax.set_xlim(0, r.time[-1] if len(r.time) else 1.0)
    else:
        # One marker per (interval, grid point) in contact: contacts at single frets stay
        # visible whatever the resolution; the strongest are drawn last, on top.
        force = r.map_force[rows, points]
        order = np.argsort(force)
        # Three decades below the strongest contact, labelled at 1, 2 and 5 of each decade.
        low, high = max(force.min(), force.max() * 1e-3), force.max()
        image = ax.scatter(r.map_time[rows[order]], r.grid_x[points[order]], c=force[order], s=6, marker="s",
                           linewidths=0, cmap="viridis", norm=LogNorm(vmin=low, vmax=high))
        bar = fig.colorbar(image, ax=ax, label="largest contact force per interval (N/m)")
        bar.set_ticks(colour_ticks(low, high, np))
        bar.set_ticklabels([f"{v:.3g}" for v in colour_ticks(low, high, np)])
        margin = 0.02 * r.length
        low = min([r.grid_x[points].min()] + list(r.played_position - r.played_width / 2))
        high = max([r.grid_x[points].max()] + list(r.played_position + r.played_width / 2))
        ax.set_ylim(max(0.0, low - margin), min(r.length, high + margin))
        # Contacts often last a fraction of the run (the pop: 80 ms of 3 s): show their span.
        last = r.map_time[rows].max()
        ax.set_xlim(0, min(r.map_time[-1], 1.1 * last + (r.map_time[1] - r.map_time[0] if len(r.map_time) > 1 else 0.0)))
    draw_played_pads(ax, r)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("x (m)")
    ax.set_title(f"{r.case}: contactogram")
    save(fig, directory, "contactogram.png", written)
    plt.close(fig)


PLAYED_COLOURS = {"finger": "C3", "pluck": "C1", "pop": "C1", "force": "C4"}


def draw_played_pads(ax, r):
    """The pads of the fingers and gestures as labelled bands across the contactogram (their
    own forces are in the map there, beside the obstacle's)."""
    for kind, x, w in zip(r.played_kind, r.played_position, r.played_width):
        half = max(w / 2, 0.002 * r.length)  # a point force: a thin band
        ax.axhspan(x - half, x + half, color=PLAYED_COLOURS.get(kind, "C7"), alpha=0.15, lw=0)
        ax.text(0.995, x, f" {kind} ", transform=ax.get_yaxis_transform(), ha="right", va="center", fontsize=8,
                color=PLAYED_COLOURS.get(kind, "C7"))


def played_at(r, t, np):
    """(kind, x, width, height in mm or None) of each finger and gesture at time t: the
    height of the stored row nearest to t (None: a force gesture, or a plucker not there)."""
    parts = []
    rows = len(r.played_height)
    k = int(np.argmin(np.abs(r.energy_time[:rows] - t))) if rows else -1
    for p, (kind, x, w) in enumerate(zip(r.played_kind, r.played_position, r.played_width)):
        h = r.played_height[k, p] if k >= 0 else float("nan")
        parts.append((kind, x, w, None if not np.isfinite(h) else h * 1e3))
    return parts


def draw_played(ax, r, t, np, artists=None):
    """Fingers' pads and pluckers as thick bars at their heights, force gestures as a
    dashed line at their place; with `artists` (from a first call), moves those instead."""
    made = []
    for p, (kind, x, w, h) in enumerate(played_at(r, t, np)):
        xs = [x - w / 2, x + w / 2]
        ys = [h, h] if h is not None else [float("nan")] * 2
        if artists is not None:
            if kind != "force":
                artists[p].set_data(xs, ys)
            continue
        if kind == "force":
            made.append(ax.axvline(x, color=PLAYED_COLOURS["force"], ls="--", lw=0.8))
        else:
            made.append(ax.plot(xs, ys, color=PLAYED_COLOURS.get(kind, "C7"), lw=4, solid_capstyle="butt",
                                label=kind)[0])
    return made if artists is None else artists


def colour_ticks(low, high, np):
    """Ticks at 1, 2, 5 x 10^k between low and high (and the ends when fewer than three fall inside)."""
    ticks = [m * 10.0 ** k for k in range(int(np.floor(np.log10(low))), int(np.ceil(np.log10(high))) + 1)
             for m in (1, 2, 5) if low <= m * 10.0 ** k <= high]
    return ticks if len(ticks) >= 3 else sorted(set(ticks) | {low, high})


def draw_obstacle(ax, r, np, floor):
    """The obstacle as a grey region from its height g(x) down to `floor` (mm)."""
    finite = np.isfinite(r.obstacle)
    if not finite.any():
        return
    g = np.where(finite, r.obstacle, np.nan) * 1e3
    ax.fill_between(r.grid_x, floor, g, where=finite, color="0.75", step="mid", lw=0)
    if finite.sum() < 20:  # isolated points (a single fret): make them visible
        ax.plot(r.grid_x[finite], g[finite], "v", color="0.4", ms=5)


def string_curve(r, u, np):
    """The shape with the fixed ends added, in mm."""
    return np.concatenate([[0.0], r.grid_x, [r.length]]), np.concatenate([[0.0], u, [0.0]]) * 1e3


def shape_limits(r, np):
    """Vertical range (mm): the string's motion, and the obstacle only where it is near."""
    low, high = min(r.snapshots.min(), 0.0) * 1e3, max(r.snapshots.max(), 0.0) * 1e3
    span = high - low if high > low else 1.0
    finite = r.obstacle[np.isfinite(r.obstacle)] * 1e3
    if finite.size:
        low = max(min(low, finite.min()), low - 0.5 * span)
    pad = 0.08 * (high - low)
    return low - pad, high + pad


def plot_snapshots(r, plt, np, directory, written):
    count = min(SNAPSHOT_PANELS, len(r.snapshot_time))
    chosen = np.unique(np.linspace(0, len(r.snapshot_time) - 1, count).round().astype(int))
    fig, axes = plt.subplots(len(chosen), 1, figsize=(10, 1.5 * len(chosen) + 1), sharex=True, sharey=True,
                             layout="constrained", squeeze=False)
    limits = shape_limits(r, np)
    for ax, k in zip(axes[:, 0], chosen):
        draw_obstacle(ax, r, np, limits[0])
        ax.plot(*string_curve(r, r.snapshots[k], np), color="C0", lw=1.0)
        draw_played(ax, r, r.snapshot_time[k], np)
        ax.set_ylim(*limits)
        ax.text(0.01, 0.85, f"t = {r.snapshot_time[k] * 1e3:.3f} ms", transform=ax.transAxes, fontsize=9)
        ax.set_ylabel("u (mm)")
    axes[0, 0].set_title(f"{r.case}: string shapes")
    if any(kind != "force" for kind in r.played_kind):
        axes[0, 0].legend(loc="upper right", fontsize=8)
    axes[-1, 0].set_xlabel("x (m)")
    axes[-1, 0].set_xlim(0, r.length)
    save(fig, directory, "snapshots.png", written)
    plt.close(fig)


def animate(r, plt, np, directory, written, form):
    from matplotlib import animation

    frames = np.unique(np.linspace(0, len(r.snapshot_time) - 1, min(MAX_ANIMATION_FRAMES, len(r.snapshot_time)))
                       .round().astype(int))
    fig, ax = plt.subplots(figsize=(8, 3), layout="constrained")
    limits = shape_limits(r, np)
    draw_obstacle(ax, r, np, limits[0])
    line, = ax.plot(*string_curve(r, r.snapshots[frames[0]], np), color="C0", lw=1.2)
    label = ax.text(0.01, 0.9, "", transform=ax.transAxes)
    pads = draw_played(ax, r, r.snapshot_time[frames[0]], np)
    ax.set_xlim(0, r.length)
    ax.set_ylim(*limits)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("u (mm)")
    ax.set_title(r.case)

    def draw(k):
        line.set_ydata(string_curve(r, r.snapshots[k], np)[1])
        label.set_text(f"t = {r.snapshot_time[k] * 1e3:.3f} ms")
        draw_played(ax, r, r.snapshot_time[k], np, pads)
        return (line, label, *pads)

    movie = animation.FuncAnimation(fig, draw, frames=frames, blit=True)
    if form == "mp4":
        if shutil.which("ffmpeg") is None:
            print("fretbuzz plot: ffmpeg not found (apt-get install ffmpeg); no animation.mp4", file=sys.stderr)
            plt.close(fig)
            return
        writer, name = animation.FFMpegWriter(fps=20, codec="libx264", extra_args=["-pix_fmt", "yuv420p"]), \
            "animation.mp4"
    else:
        writer, name = animation.PillowWriter(fps=15), "animation.gif"
    path = os.path.join(directory, name)
    movie.save(path, writer=writer, dpi=ANIMATION_DPI)
    written.append(path)
    plt.close(fig)


def remove_stale(directory, names):
    """Figures an earlier run in the same directory may have left but this one cannot make."""
    for name in names:
        path = os.path.join(directory, name)
        if os.path.isfile(path):
            os.remove(path)


def plot_directory(directory, animation="none", formats=("png",), quiet=True, zoom=None, db_range=DB_RANGE,
                   max_frequency=MAX_FREQUENCY):
    """Draws every figure of the run in `directory` (holding results.h5); returns the paths written.

    formats: any of "png", "pdf", "svg". zoom: the zoomed windows of signal.png as (start,
    end) pairs in s (default: the first contacts, the middle, the end). db_range: the
    spectrogram's colour range below its peak (dB), up to max_frequency (Hz).

    Keeps the current Matplotlib backend (inline figures in notebooks are closed after saving).
    """
    import h5py
    import matplotlib.pyplot as plt
    import numpy as np

    unknown = set(formats) - {"png", "pdf", "svg"}
    if unknown or not formats:
        raise ValueError(f"formats: must be some of png, pdf, svg, got {sorted(unknown) or 'none'}")
    FORMATS[:] = list(formats)
    if not db_range > 0 or not max_frequency > 0:
        raise ValueError(f"db_range and max_frequency: must be > 0, got {db_range} and {max_frequency}")
    OPTIONS.update(zoom=[tuple(map(float, w)) for w in zoom] if zoom else None, db_range=float(db_range),
                   max_frequency=float(max_frequency))
    path = os.path.join(directory, "results.h5")
    if not os.path.isfile(path):
        raise FileNotFoundError(f"DIR {directory}: holds no results.h5")
    r = Results(path, h5py, np)
    written = []
    plot_signal(r, plt, np, directory, written)
    if len(r.points) > 1:
        plot_all_points(r, plt, directory, written)
    else:
        remove_stale(directory, ["signal_all_points.png"])
    plot_spectrogram(r, plt, np, directory, written)
    if r.displacement_y is not None:
        plot_spectrogram(r, plt, np, directory, written, polarisation="y")
        plot_orbit(r, plt, np, directory, written)
    else:
        remove_stale(directory, ["spectrogram_y.png", "orbit.png"])
    plot_energy(r, plt, np, directory, written)
    plot_contactogram(r, plt, np, directory, written)
    if len(r.snapshot_time):
        plot_snapshots(r, plt, np, directory, written)
        if animation != "none":
            animate(r, plt, np, directory, written, animation)
    else:
        remove_stale(directory, ["snapshots.png", "animation.gif", "animation.mp4"])
    if not quiet:
        for name in written:
            print(f"fretbuzz plot: wrote {name}", file=sys.stderr)
    return written


def plot_strings(directory, formats=("png",), quiet=True):
    """strings_energy.png of a run of strings on a bridge (strings.csv in `directory`): each
    string's energy and the bridge's over time, on a log scale (a sympathetic string takes up
    orders of magnitude less than the one played), and the assembly's balance. Returns the
    paths written."""
    import matplotlib.pyplot as plt
    import numpy as np

    FORMATS[:] = list(formats)
    path = os.path.join(directory, "strings.csv")
    with open(path) as f:
        names = f.readline().strip().split(",")
    data = np.atleast_2d(np.loadtxt(path, delimiter=",", skiprows=1))
    column = {name: data[:, i] for i, name in enumerate(names)}
    strings = [n for n in names if n not in ("t", "bridge", "balance")]
    fig, (ax, err) = plt.subplots(2, 1, figsize=(10, 6.5), sharex=True, layout="constrained",
                                  gridspec_kw={"height_ratios": [3, 1]})
    for k, name in enumerate(strings):
        ax.semilogy(column["t"], np.maximum(column[name], 1e-30), label=name, color=f"C{k % 10}",
                    ls="-" if k < 10 else "--", lw=1.0)
    ax.semilogy(column["t"], np.maximum(column["bridge"], 1e-30), label="bridge", color="k", lw=1.4)
    top = max(float(np.max(column[n])) for n in strings + ["bridge"])
    ax.set_ylim(max(top * 1e-9, 1e-30), top * 3.0)
    ax.set_ylabel("energy (J)")
    ax.set_title("energy of each string and of the bridge: the energy passing between the strings")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    err.semilogy(column["t"], np.maximum(np.abs(column["balance"]), 1e-18), color="k", lw=0.8)
    err.set_ylabel("|balance|")
    err.set_xlabel("t (s)")
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    written = []
    save(fig, directory, "strings_energy.png", written, description="curves: " + ", ".join(labels))
    plt.close(fig)
    if not quiet:
        for name in written:
            print(f"fretbuzz plot: wrote {name}", file=sys.stderr)
    return written


def read_csv_columns(path, np):
    """A numeric CSV written by fretbuzz (header line starting with '#'), as named columns."""
    with open(path) as f:
        names = f.readline().lstrip("#").strip().split(",")
    data = np.atleast_2d(np.loadtxt(path, delimiter=",", comments="#", usecols=range(len(names))))
    return {name: data[:, i] for i, name in enumerate(names)}


def plot_estimate(directory, quiet):
    """estimate.png of `fretbuzz estimate DIR`: the measured partials against the fitted
    models, as deviation from harmonic in cents and as sigma and Q against frequency."""
    try:
        import matplotlib
        import numpy as np
    except ImportError as error:
        print(f"fretbuzz estimate: {error}; the plot needs numpy and matplotlib", file=sys.stderr)
        return 1
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    measured = read_csv_columns(os.path.join(directory, "partials.csv"), np)
    model = read_csv_columns(os.path.join(directory, "model_curves.csv"), np)
    with open(os.path.join(directory, "fit.json")) as f:
        fit = json.load(f)
    f0 = fit["frequency_model"]["f0_hz"]
    top = measured["mode"].max()
    shown = model["mode"] <= max(top * 1.5, top + 5)
    reliable = measured["reliable"] > 0.5
    harmonic = measured["mode"] * f0

    fig, axes = plt.subplots(3, 1, figsize=(8, 10), sharex=True)
    cents_model = 1200 * np.log2(model["frequency_hz"] / (model["mode"] * f0))
    axes[0].plot(model["frequency_hz"][shown], cents_model[shown], "-", color="C0",
                 label=f"inharmonicity law, B = {fit['frequency_model']['B']:.3g}")
    for mask, style, label in ((reliable, "o", "measured (reliable)"), (~reliable, "x", "measured (not reliable)")):
        axes[0].plot(measured["frequency_hz"][mask], 1200 * np.log2(measured["frequency_hz"][mask] / harmonic[mask]),
                     style, color="C1", label=label)
    axes[0].set_ylabel(f"deviation from j f0 (cents), f0 = {f0:.4g} Hz")
    axes[0].legend()
    damping = fit["damping_model"]
    axes[1].semilogy(model["frequency_hz"][shown], model["sigma_per_s"][shown], "-", color="C0",
                     label=f"damping model: delta_ve = {damping['delta_ve']:.3g}, 1/Q_te = {damping['Q_te_inv']:.3g}")
    q_model = np.pi * model["frequency_hz"] / model["sigma_per_s"]
    axes[2].semilogy(model["frequency_hz"][shown], q_model[shown], "-", color="C0", label="damping model")
    for mask, style in ((reliable, "o"), (~reliable, "x")):
        axes[1].semilogy(measured["frequency_hz"][mask], measured["sigma_per_s"][mask], style, color="C1")
        axes[2].semilogy(measured["frequency_hz"][mask], measured["quality_factor"][mask], style, color="C1")
    axes[1].set_ylabel("sigma (1/s)")
    axes[1].legend()
    axes[2].set_ylabel("Q = pi nu / sigma")
    axes[2].set_xlabel("frequency (Hz)")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    written = []
    save(fig, directory, "estimate.png", written)
    if not quiet:
        print(f"fretbuzz estimate: wrote {written[0]}", file=sys.stderr)
    return 0


def plot_convergence(csv_path, image_path, title, threshold, name):
    """The log-log plot of `fretbuzz convergence`: relative L2 error against fs or K, with
    the observed orders and the threshold."""
    import csv

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    threshold = float(threshold)
    with open(csv_path) as f:
        rows = list(csv.DictReader(f))
    values = [float(r["value"]) for r in rows]
    errors = [float(r["relative_error"]) for r in rows]
    fig, ax = plt.subplots(figsize=(6.4, 4.2), dpi=100)
    ax.loglog(values, errors, "o-", label="relative L2 error")
    ax.axhline(threshold, color="tab:red", ls="--", lw=1, label=f"threshold {threshold:g}")
    for v, e, r in zip(values, errors, rows):
        if r["observed_order"]:
            ax.annotate(f"{float(r['observed_order']):.2f}", (v, e), textcoords="offset points", xytext=(4, 6),
                        fontsize=8)
    ax.set_xlabel("fs (Hz)" if name == "fs" else "K (N/m^alpha+1)")
    ax.set_ylabel("relative L2 error")
    ax.set_title(title, fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(image_path)
    plt.close(fig)
    return 0


def main(argv):
    if argv[:1] == ["--convergence"]:
        return plot_convergence(*argv[1:6])
    if argv[:1] == ["--estimate"]:
        return plot_estimate(argv[1], "--quiet" in argv[2:])
    args = parse_arguments(argv)
    try:
        import h5py  # noqa: F401
        import matplotlib
        import numpy  # noqa: F401
    except ImportError as error:
        print(f"fretbuzz plot: {error}; this needs numpy, matplotlib and h5py "
              "(Debian: apt-get install python3-numpy python3-matplotlib python3-h5py)", file=sys.stderr)
        return 1
    matplotlib.use("Agg")
    if not os.path.isfile(os.path.join(args.dir, "results.h5")) and os.path.isfile(os.path.join(args.dir, "strings.csv")):
        plot_strings(args.dir, formats=args.formats or ["png"], quiet=args.quiet)
        return 0
    if not os.path.isfile(os.path.join(args.dir, "results.h5")):
        print(f"fretbuzz plot: DIR {args.dir}: holds no results.h5", file=sys.stderr)
        return 2
    plot_directory(args.dir, animation=args.animation, formats=args.formats or ["png"], quiet=args.quiet,
                   zoom=args.zoom, db_range=args.db_range, max_frequency=args.max_frequency)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
