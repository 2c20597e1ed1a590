#pragma once
// The string's models fitted to estimated partials (Issanchou et al. 2017, section 4):
// the inharmonicity law nu_j = f0 j (stiffness factor of B j^2) by weighted least squares
// on f0 and B, and the damping model's viscoelastic loss delta_ve, thermoelastic 1/Q_te
// (and optionally the air term's equivalent diameter) by non-negative least squares on
// 1/Q_j. Both evaluate the product's FrequencyModel and DampingModel, so the fitted
// numbers mean exactly what the case file's [modes.frequency] and [modes.damping] mean.
#include <cstddef>
#include <optional>
#include <span>
#include <vector>

#include "fretbuzz/analysis/ModalEstimation.hpp"
#include "fretbuzz/model/DampingModel.hpp"
#include "fretbuzz/model/ModeTable.hpp"
#include "fretbuzz/model/TautString.hpp"

namespace fretbuzz {

struct FrequencyLaw {
    double f0_hz = 0.0;          // c / (2L)
    double inharmonicity = 0.0;  // B
    double rms_cents = 0.0;      // fit quality over the modes used
    double max_cents = 0.0;
    std::size_t points = 0;

    double frequency_hz(std::size_t mode) const;  // the product's FrequencyModel
};

// Least squares on relative frequency errors; B >= 0 is fitted only from 3 modes on.
FrequencyLaw fit_frequency_law(std::span<const std::size_t> modes, std::span<const double> frequency_hz);

struct StringParameters {
    double length_m = 0.0;                  // L
    std::optional<double> tension_n;        // T; when absent, from f0: T = mu (2 L f0)^2
    double linear_density = 0.0;            // mu
    double diameter_m = 0.0;                // d (air friction)
};

struct DampingFit {
    DampingParameters parameters;      // delta_ve, 1/Q_te, d_eq as fitted (E_core I_core from B)
    bool air_fitted = false;           // d_eq fitted rather than taken as d
    double rms_relative_error = 0.0;   // of sigma, over the modes used
    double max_relative_error = 0.0;
    std::size_t points = 0;
};

struct StringFit {
    FrequencyLaw frequency;
    TautString string;        // with the tension that gives the fitted f0
    double given_tension_n = 0.0;  // 0 when none was given
    DampingFit damping;
};

class ModelFit {
public:
    ModelFit(StringParameters properties, bool fit_air = false);

    // Fits both models to the reliable partials of polarisation 1 (each mode's stronger
    // partial); throws InputError if fewer than 2.
    StringFit fit(const ModalEstimate& estimate) const;
    // Modes 1..mode_count (the z polarisation): the reliable measurements of each mode's
    // stronger partial, the fitted models elsewhere.
    static ModeTable mode_table(const StringFit& fit, const ModalEstimate& estimate, std::size_t mode_count);
    // The y polarisation's modes, as many as z has: the weaker partial of each reliably
    // resolved doublet, and z's mode where none was (the two coincide within the resolution).
    static ModeTable y_mode_table(const ModeTable& z, const ModalEstimate& estimate);

private:
    StringParameters properties_;
    bool fit_air_;
};

}  // namespace fretbuzz
