#pragma once
// What reaches the ear through an electric bass's rig, as a power gain per frequency that the
// listener weighs the pickup's spectra by (analysis/Listener.hpp weighs by it):
//  - the magnetic pickup, an inductive source: its coil (inductance L, resistance R) drives
//    its own winding capacitance and the cable's (C) in parallel with the controls and the
//    amplifier's input (R_load). Its electromotive force follows the string's velocity; what
//    the amplifier sees is that force through
//        H(s) = (1 + R/R_load) / (L C s^2 + (R C + L/R_load) s + 1 + R/R_load),
//    a second-order low-pass with a resonance near 1/(2 pi sqrt(L C)) (H. Lemme, "The secrets
//    of electric guitar pickups", 2003: with a cable, 2 to 5 kHz, 0 to 12 dB high);
//  - the amplifier and speaker's band: a Butterworth low-pass at the cabinet's upper limit
//    and a second-order high-pass at its lower one.
// Only the magnitude matters to the listener (band energies ignore phase), and the circuit's
// ring (about a millisecond) is far shorter than the listener's frames (40 ms and more), so
// weighing each frame's spectrum by |H|^2 is filtering the signal. The figures, with their
// sources, are cases/rigs/STYLE.toml's; an instrument file's [rig] overrides any of them.
#include <complex>

namespace fretbuzz {

struct PickupCircuit {
    double inductance_h = 3.0;
    double resistance_ohm = 6800.0;
    double capacitance_f = 650e-12;  // the winding's and the cable's
    double load_ohm = 111e3;         // the controls and the amplifier's input, in parallel
};

struct RigSettings {
    PickupCircuit pickup;
    double speaker_high_hz = 4000.0;  // the cabinet's upper -3 dB point
    int speaker_order = 4;            // of its Butterworth low-pass
    double speaker_low_hz = 40.0;     // its lower -3 dB point (second order)
};

class ListeningRig {
public:
    // InputError naming the figure when one is not positive and finite.
    explicit ListeningRig(const RigSettings& settings);
    // The loaded pickup's response (1 at 0 Hz) at f.
    std::complex<double> pickup_response(double frequency_hz) const;
    // |pickup|^2 |speaker|^2 at f: what the listener weighs the pickup's spectrum by.
    double power_gain(double frequency_hz) const;
    // Where the loaded pickup's response peaks, and how high (dB above its 0 Hz gain; 0 when
    // it has no peak).
    double resonance_hz() const { return resonance_hz_; }
    double resonance_peak_db() const { return peak_db_; }
    const RigSettings& settings() const { return settings_; }

private:
    RigSettings settings_;
    double resonance_hz_ = 0.0, peak_db_ = 0.0;
};

}  // namespace fretbuzz
