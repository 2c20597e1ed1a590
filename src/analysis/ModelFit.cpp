#include "fretbuzz/analysis/ModelFit.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/model/FrequencyModel.hpp"
#include "fretbuzz/model/ModeTableAssembly.hpp"

namespace fretbuzz {

namespace {

using std::numbers::pi;

// The product's frequency law for f0 = 1 Hz: a string with c = 1 m/s, L = 0.5 m.
double unit_law(std::size_t mode, double inharmonicity) {
    return FrequencyModel(TautString{0.5, 1.0, 1.0}, inharmonicity).frequency_hz(mode);
}

struct LawResidual {
    double f0 = 0.0;
    double cost = 0.0;
};

// For a given B the best f0 is closed form (weights 1/nu^2: relative errors).
LawResidual best_f0(std::span<const std::size_t> modes, std::span<const double> nu, double b) {
    double num = 0.0, den = 0.0;
    for (std::size_t i = 0; i < modes.size(); ++i) {
        const double r = unit_law(modes[i], b);
        num += r / nu[i];
        den += r * r / (nu[i] * nu[i]);
    }
    LawResidual out{num / den, 0.0};
    for (std::size_t i = 0; i < modes.size(); ++i) {
        const double e = (nu[i] - out.f0 * unit_law(modes[i], b)) / nu[i];
        out.cost += e * e;
    }
    return out;
}

double cents(double measured, double model) { return 1200.0 * std::log2(measured / model); }

}  // namespace

double FrequencyLaw::frequency_hz(std::size_t mode) const { return f0_hz * unit_law(mode, inharmonicity); }

FrequencyLaw fit_frequency_law(std::span<const std::size_t> modes, std::span<const double> frequency_hz) {
    FrequencyLaw law;
    law.points = modes.size();
    if (modes.empty()) return law;
    double b = 0.0;
    if (modes.size() >= 3) {
        // sqrt(B) on a grid up to B = 0.01, then golden-section refinement around the best.
        constexpr int kGrid = 200;
        constexpr double kMaxRoot = 0.1;
        int best = 0;
        double best_cost = best_f0(modes, frequency_hz, 0.0).cost;
        for (int i = 1; i <= kGrid; ++i) {
            const double s = kMaxRoot * i / kGrid;
            const double cost = best_f0(modes, frequency_hz, s * s).cost;
            if (cost < best_cost) best_cost = cost, best = i;
        }
        double lo = kMaxRoot * std::max(0, best - 1) / kGrid, hi = kMaxRoot * std::min(kGrid, best + 1) / kGrid;
        const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
        for (int it = 0; it < 80; ++it) {
            const double a = hi - ratio * (hi - lo), c = lo + ratio * (hi - lo);
            if (best_f0(modes, frequency_hz, a * a).cost < best_f0(modes, frequency_hz, c * c).cost)
                hi = c;
            else
                lo = a;
        }
        b = 0.25 * (lo + hi) * (lo + hi);
    }
    law.inharmonicity = b;
    law.f0_hz = best_f0(modes, frequency_hz, b).f0;
    double sum = 0.0;
    for (std::size_t i = 0; i < modes.size(); ++i) {
        const double c = cents(frequency_hz[i], law.frequency_hz(modes[i]));
        sum += c * c;
        law.max_cents = std::max(law.max_cents, std::abs(c));
    }
    law.rms_cents = std::sqrt(sum / static_cast<double>(modes.size()));
    return law;
}

ModelFit::ModelFit(StringParameters properties, bool fit_air) : properties_(properties), fit_air_(fit_air) {
    require_positive("string L (m)", properties_.length_m);
    require_positive("string mu (kg/m)", properties_.linear_density);
    require_positive("string d (m)", properties_.diameter_m);
    if (properties_.tension_n) require_positive("string T (N)", *properties_.tension_n);
}

StringFit ModelFit::fit(const ModalEstimate& estimate) const {
    std::vector<std::size_t> modes;
    std::vector<double> nu, sigma;
    for (const EstimatedPartial& p : estimate.partials)
        if (p.reliable && p.polarisation == 1) {
            modes.push_back(p.mode);
            nu.push_back(p.frequency_hz);
            sigma.push_back(p.sigma_per_s);
        }
    if (modes.size() < 2)
        throw InputError("recording: " + std::to_string(modes.size()) +
                         " reliable partial(s) found; the models need at least 2 (a longer or cleaner decay)");
    StringFit out;
    out.frequency = fit_frequency_law(modes, nu);
    const double f0 = out.frequency.f0_hz;
    out.given_tension_n = properties_.tension_n.value_or(0.0);
    // The tension that puts nu_0j = j f0 exactly: the frequency model must reproduce the measurement.
    out.string = TautString{properties_.length_m,
                            properties_.linear_density * std::pow(2.0 * properties_.length_m * f0, 2),
                            properties_.linear_density};

    // 1/Q_j = air_j + delta_ve * ve_j + 1/Q_te (+ d_eq * air_per_m_j when the air term is fitted),
    // each column evaluated by the product's DampingModel with one parameter switched on.
    DampingParameters base;
    base.equivalent_diameter_m = fit_air_ ? 0.0 : properties_.diameter_m;
    DampingParameters ve_only;
    ve_only.air_viscosity = 0.0;
    ve_only.viscoelastic_loss = 1.0;
    ve_only.core_bending_stiffness = out.string.bending_stiffness_for(out.frequency.inharmonicity);
    DampingParameters unit_diameter = base;
    unit_diameter.equivalent_diameter_m = 1.0;
    const DampingModel fixed(out.string, base), ve(out.string, ve_only), per_metre(out.string, unit_diameter);

    const auto n = static_cast<Eigen::Index>(modes.size());
    const Eigen::Index columns = fit_air_ ? 3 : 2;
    Eigen::MatrixXd a(n, columns);
    Eigen::VectorXd rhs(n);
    for (Eigen::Index i = 0; i < n; ++i) {
        const auto ui = static_cast<std::size_t>(i);
        const double measured = sigma[ui] / (pi * nu[ui]);
        const double w = 1.0 / measured;  // relative errors
        rhs(i) = w * (measured - fixed.inverse_q(modes[ui], nu[ui]));
        a(i, 0) = w * ve.inverse_q(modes[ui], nu[ui]);
        a(i, 1) = w;
        if (fit_air_) a(i, 2) = w * (per_metre.inverse_q(modes[ui], nu[ui]) - fixed.inverse_q(modes[ui], nu[ui]));
    }
    // Non-negative least squares by trying every subset of free parameters (at most 8).
    Eigen::VectorXd best = Eigen::VectorXd::Zero(columns);
    double best_cost = rhs.squaredNorm();
    for (int mask = 1; mask < (1 << columns); ++mask) {
        std::vector<Eigen::Index> used;
        for (Eigen::Index c = 0; c < columns; ++c)
            if (mask & (1 << c)) used.push_back(c);
        Eigen::MatrixXd sub(n, static_cast<Eigen::Index>(used.size()));
        for (std::size_t k = 0; k < used.size(); ++k) sub.col(static_cast<Eigen::Index>(k)) = a.col(used[k]);
        const Eigen::VectorXd x = sub.colPivHouseholderQr().solve(rhs);
        if ((x.array() < 0.0).any()) continue;
        const double cost = (sub * x - rhs).squaredNorm();
        if (cost < best_cost) {
            best_cost = cost;
            best.setZero();
            for (std::size_t k = 0; k < used.size(); ++k) best(used[k]) = x(static_cast<Eigen::Index>(k));
        }
    }
    DampingParameters& p = out.damping.parameters;
    p.viscoelastic_loss = best(0);
    p.core_bending_stiffness = ve_only.core_bending_stiffness;
    p.thermoelastic_inverse_q = best(1);
    p.equivalent_diameter_m = fit_air_ ? best(2) : properties_.diameter_m;
    out.damping.air_fitted = fit_air_;
    out.damping.points = modes.size();
    const DampingModel model(out.string, p);
    double sum = 0.0;
    for (std::size_t i = 0; i < modes.size(); ++i) {
        const double e = model.sigma_per_s(modes[i], nu[i]) / sigma[i] - 1.0;
        sum += e * e;
        out.damping.max_relative_error = std::max(out.damping.max_relative_error, std::abs(e));
    }
    out.damping.rms_relative_error = std::sqrt(sum / static_cast<double>(modes.size()));
    return out;
}

ModeTable ModelFit::mode_table(const StringFit& fit, const ModalEstimate& estimate, std::size_t mode_count) {
    std::vector<MeasuredMode> measured;
    for (const EstimatedPartial& p : estimate.partials)
        if (p.reliable && p.polarisation == 1) measured.push_back({p.mode, p.frequency_hz, p.sigma_per_s});
    const FrequencyModel frequency(fit.string, fit.frequency.inharmonicity);
    const DampingModel damping(fit.string, fit.damping.parameters);
    return assemble_mode_table(mode_count, measured, &frequency, &damping);
}

ModeTable ModelFit::y_mode_table(const ModeTable& z, const ModalEstimate& estimate) {
    ModeTable y = z;
    for (const EstimatedPartial& p : estimate.partials)
        if (p.reliable && p.polarisation == 2 && p.mode <= y.size()) {
            y.frequency_hz[p.mode - 1] = p.frequency_hz;
            y.sigma_per_s[p.mode - 1] = p.sigma_per_s;
            y.source[p.mode - 1] = ModeSource::measured;
        }
    return y;
}

}  // namespace fretbuzz
