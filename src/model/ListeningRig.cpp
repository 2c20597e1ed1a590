#include "fretbuzz/model/ListeningRig.hpp"

#include <cmath>
#include <numbers>
#include <string>

#include "fretbuzz/Error.hpp"

namespace fretbuzz {

namespace {

void check_positive(double value, const char* name) {
    if (!(value > 0.0 && std::isfinite(value))) throw InputError(out_of_range_message(name, value, "must be > 0"));
}

}  // namespace

ListeningRig::ListeningRig(const RigSettings& settings) : settings_(settings) {
    const PickupCircuit& p = settings.pickup;
    check_positive(p.inductance_h, "rig.pickup_inductance (H)");
    check_positive(p.resistance_ohm, "rig.pickup_resistance (ohm)");
    check_positive(p.capacitance_f, "rig.capacitance (F)");
    check_positive(p.load_ohm, "rig.load (ohm)");
    check_positive(settings.speaker_high_hz, "rig.speaker_high (Hz)");
    check_positive(settings.speaker_low_hz, "rig.speaker_low (Hz)");
    if (settings.speaker_order < 1 || settings.speaker_order > 8)
        throw InputError(out_of_range_message("rig.speaker_order", settings.speaker_order, "must be in [1, 8]"));
    if (!(settings.speaker_low_hz < settings.speaker_high_hz))
        throw InputError("rig.speaker_low must lie below rig.speaker_high");
    // |H|^2 = g^2 / ((g - LC w^2)^2 + (b w)^2), g = 1 + R/R_load, b = RC + L/R_load: its
    // denominator, a quadratic in w^2, is least at w^2 = (2 g LC - b^2) / (2 (LC)^2).
    const double lc = p.inductance_h * p.capacitance_f;
    const double g = 1.0 + p.resistance_ohm / p.load_ohm;
    const double b = p.resistance_ohm * p.capacitance_f + p.inductance_h / p.load_ohm;
    const double w2 = (2.0 * g * lc - b * b) / (2.0 * lc * lc);
    if (w2 > 0.0) {
        resonance_hz_ = std::sqrt(w2) / (2.0 * std::numbers::pi);
        peak_db_ = 20.0 * std::log10(std::abs(pickup_response(resonance_hz_)));
    }
}

std::complex<double> ListeningRig::pickup_response(double frequency_hz) const {
    const PickupCircuit& p = settings_.pickup;
    const std::complex<double> s(0.0, 2.0 * std::numbers::pi * frequency_hz);
    const double g = 1.0 + p.resistance_ohm / p.load_ohm;
    return g / (p.inductance_h * p.capacitance_f * s * s +
                (p.resistance_ohm * p.capacitance_f + p.inductance_h / p.load_ohm) * s + g);
}

double ListeningRig::power_gain(double frequency_hz) const {
    const double pickup = std::norm(pickup_response(frequency_hz));
    const double high = std::pow(frequency_hz / settings_.speaker_high_hz, 2 * settings_.speaker_order);
    const double low = std::pow(frequency_hz / settings_.speaker_low_hz, 4);
    return pickup / (1.0 + high) * low / (1.0 + low);
}

}  // namespace fretbuzz
