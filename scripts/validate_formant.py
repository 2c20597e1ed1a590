#!/usr/bin/env /usr/bin/python3
"""The paper's formant near 4.5 kHz, read as its Figure 3 shows it: a spectrogram.

bass-pop at Fe = 4 MHz over 0.3 s, with its frets and with the obstacle removed, observed at
0.854 m. Short-time spectra (20 ms Hann frames, hop 5 ms) are averaged over the contact phase
(5-80 ms) and over the free decay after it (150-300 ms), then smoothed over 500 Hz. The script
prints the level of the contact-phase spectrum at 3 to 7 kHz, the local peak near 4.5 kHz and
its prominence over its neighbours, and writes docs/figures/bass_pop_formant_spectrogram.png."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import validation_common as common  # noqa: E402

RATE = 48000
CONTACT_PHASE = (0.005, 0.080)
FREE_PHASE = (0.150, 0.300)


def run(case, label):
    out = common.scratch_dir(label)
    common.fretbuzz("run", case, "--duration", 0.3, "--output-rate", RATE, "--out", out, "-q")
    _, data = common.read_csv(out / "observation.csv")
    return data[:, 0], data[:, 1]


def averaged_spectrum(t, u, span, frame=0.02, hop=0.005):
    rate = 1.0 / (t[1] - t[0])
    width, step = int(frame * rate), int(hop * rate)
    window = np.hanning(width)
    frames = [np.abs(np.fft.rfft(u[s:s + width] * window)) ** 2
              for s in range(0, len(u) - width, step) if span[0] <= t[s + width // 2] <= span[1]]
    freq = np.fft.rfftfreq(width, 1.0 / rate)
    power = np.mean(frames, axis=0)
    bins = max(1, int(500.0 / (freq[1] - freq[0])))
    return freq, np.convolve(power, np.ones(bins) / bins, "same")


def level_at(freq, power, f):
    return 10.0 * np.log10(power[np.argmin(np.abs(freq - f))])


def main():
    scratch = common.scratch_dir("formant-cases")
    t, fretted = run("bass-pop", "fretted")
    _, free = run(common.case_variant("bass-pop", scratch, obstacle_none=True), "free")
    freq, contact = averaged_spectrum(t, fretted, CONTACT_PHASE)
    _, after = averaged_spectrum(t, fretted, FREE_PHASE)
    _, free_contact = averaged_spectrum(t, free, CONTACT_PHASE)

    print("contact phase (5-80 ms), smoothed over 500 Hz, dB re 1 m^2:")
    for f in (3000, 3500, 4000, 4500, 5000, 5500, 6000, 7000):
        print(f"  {f:5d} Hz  with frets {level_at(freq, contact, f):7.1f}   no obstacle {level_at(freq, free_contact, f):7.1f}")
    band = (freq > 3800) & (freq < 5200)
    peak = freq[band][np.argmax(contact[band])]
    prominence = level_at(freq, contact, peak) - max(level_at(freq, contact, peak - 500), level_at(freq, contact, peak + 500))
    print(f"local peak of the contact-phase spectrum near 4.5 kHz: {peak:.0f} Hz, "
          f"{prominence:.1f} dB above the spectrum 500 Hz either side")

    fig, axes = plt.subplots(1, 2, figsize=(11, 3.8), layout="constrained")
    early = t <= 0.3
    axes[0].specgram(fretted[early], NFFT=960, Fs=RATE, noverlap=720, cmap="magma", vmin=-230)
    axes[0].set_ylim(0, 10000)
    axes[0].set_xlabel("t [s]")
    axes[0].set_ylabel("f [Hz]")
    axes[0].set_title("bass-pop at 0.854 m, first 0.3 s")
    for power, label in ((contact, "frets, contact phase 5-80 ms"), (after, "frets, after contacts 150-300 ms"),
                         (free_contact, "no obstacle, 5-80 ms")):
        axes[1].semilogy(freq, power, label=label, lw=1)
    axes[1].axvline(peak, color="0.4", ls=":", lw=1)
    axes[1].set_xlim(0, 10000)
    axes[1].set_xlabel("f [Hz]")
    axes[1].set_ylabel("averaged power (smoothed)")
    axes[1].legend(fontsize=8)
    fig.savefig(common.FIGURES / "bass_pop_formant_spectrogram.png", dpi=80)


if __name__ == "__main__":
    main()
