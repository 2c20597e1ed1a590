// fretbuzz.estimate: the partials of a free decay held in a NumPy array (ESPRIT per band),
// and, given the string, the fitted models and the mode table, as `fretbuzz estimate` does.
#include <pybind11/stl.h>

#include <cmath>
#include <csignal>
#include <optional>
#include <string>
#include <vector>

#include "BackgroundRun.hpp"
#include "Bindings.hpp"
#include "Conversions.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/analysis/ModalEstimation.hpp"
#include "fretbuzz/analysis/ModelFit.hpp"
#include "fretbuzz/model/ModalDamping.hpp"

namespace fretbuzz::python {

namespace py = pybind11;

namespace {

py::dict partials_dict(const ModalEstimate& e) {
    std::vector<double> mode, nu, sigma, q, amplitude, phase, snr, reliable, polarisation, nu_sd, sigma_sd, merged;
    for (const EstimatedPartial& p : e.partials) {
        mode.push_back(static_cast<double>(p.mode));
        nu.push_back(p.frequency_hz);
        sigma.push_back(p.sigma_per_s);
        q.push_back(quality_factor(p.frequency_hz, p.sigma_per_s));
        amplitude.push_back(p.amplitude);
        phase.push_back(p.phase_rad);
        snr.push_back(p.snr_db);
        reliable.push_back(p.reliable ? 1.0 : 0.0);
        polarisation.push_back(static_cast<double>(p.polarisation));
        nu_sd.push_back(p.frequency_sd_hz);
        sigma_sd.push_back(p.sigma_sd_per_s);
        merged.push_back(p.merged ? 1.0 : 0.0);
    }
    py::dict d;
    d["mode"] = to_numpy(mode);
    d["frequency_hz"] = to_numpy(nu);
    d["sigma_per_s"] = to_numpy(sigma);
    d["quality_factor"] = to_numpy(q);
    d["amplitude"] = to_numpy(amplitude);
    d["phase_rad"] = to_numpy(phase);
    d["snr_db"] = to_numpy(snr);
    d["reliable"] = to_numpy(reliable);
    d["polarisation"] = to_numpy(polarisation);
    d["frequency_sd_hz"] = to_numpy(nu_sd);
    d["sigma_sd_per_s"] = to_numpy(sigma_sd);
    d["merged"] = to_numpy(merged);
    return d;
}

py::dict table_dict(const ModeTable& table) {
    std::vector<double> measured;
    for (ModeSource source : table.source) measured.push_back(source == ModeSource::measured ? 1.0 : 0.0);
    py::dict t;
    t["frequency_hz"] = to_numpy(table.frequency_hz);
    t["sigma_per_s"] = to_numpy(table.sigma_per_s);
    t["measured"] = to_numpy(measured);
    return t;
}

py::dict estimate(const py::handle& signal, double rate_hz, std::optional<double> f0,
                  std::optional<std::vector<double>> band, std::size_t partials_per_band, std::size_t max_partial,
                  bool whiten, std::optional<py::dict> string, std::size_t modes, bool fit_air) {
    const std::vector<double> x = to_vector(signal, "signal");
    EstimationOptions options;
    options.f0_hz = f0;
    if (band) {
        if (band->size() != 2) throw InputError("band: give two frequencies, (low, high) in Hz");
        options.band_low_hz = (*band)[0];
        options.band_high_hz = (*band)[1];
    }
    options.partials_per_band = partials_per_band;
    options.max_partials = max_partial;
    options.whiten = whiten;
    // On a thread of its own (BackgroundRun): Ctrl-C is seen within 0.2 s and stops the
    // estimate at its next band; at the interpreter's end a daemon thread stops it and ends.
    BackgroundRun<int> background;
    options.checkpoint = [&background] {
        if (background.stopping()) throw Interrupted(SIGINT);
    };
    ModalEstimate e;
    background.run([&] { e = ModalEstimation(options).estimate(x, rate_hz); }, [](int) {});
    py::dict out;
    out["partials"] = partials_dict(e);
    out["f0_hz"] = e.f0_hz;
    out["B"] = e.inharmonicity;
    out["decay_start_s"] = e.start_s;
    out["bands"] = e.bands;
    out["rejected_poles"] = e.rejected_poles;
    if (!string) return out;

    StringParameters s;
    const py::dict& given = *string;
    for (const char* key : {"L", "mu", "d"})
        if (!given.contains(key)) throw InputError(std::string("string['") + key + "'] is missing (m, kg/m, m)");
    s.length_m = given["L"].cast<double>();
    s.linear_density = given["mu"].cast<double>();
    s.diameter_m = given["d"].cast<double>();
    if (given.contains("T")) s.tension_n = given["T"].cast<double>();
    const StringFit fit = ModelFit(s, fit_air).fit(e);
    const ModeTable table = ModelFit::mode_table(fit, e, modes);
    const DampingParameters& p = fit.damping.parameters;
    py::dict f;
    f["f0_hz"] = fit.frequency.f0_hz;
    f["B"] = fit.frequency.inharmonicity;
    f["rms_cents"] = fit.frequency.rms_cents;
    f["T"] = fit.string.tension_n;
    f["delta_ve"] = p.viscoelastic_loss;
    f["Q_te_inv"] = p.thermoelastic_inverse_q;
    f["d_eq"] = p.equivalent_diameter_m;
    f["sigma_rms_relative_error"] = fit.damping.rms_relative_error;
    out["fit"] = f;
    out["mode_table"] = table_dict(table);
    out["mode_table_y"] = table_dict(ModelFit::y_mode_table(table, e));
    return out;
}

}  // namespace

void bind_estimate(py::module_& m) {
    m.def("estimate", &estimate, py::arg("signal"), py::arg("rate"), py::kw_only(), py::arg("f0") = py::none(),
          py::arg("band") = py::none(), py::arg("partials_per_band") = 5, py::arg("max_partial") = 200,
          py::arg("whiten") = true, py::arg("string") = py::none(), py::arg("modes") = 100,
          py::arg("fit_air") = false,
          "Partials of a free decay (1-D array at `rate` Hz) by ESPRIT per band: a dict with 'partials'\n"
          "(mode, frequency_hz, sigma_per_s, quality_factor, amplitude, phase_rad, snr_db, reliable,\n"
          "polarisation: 1 for each mode's stronger partial, 2 for the weaker one of a resolved doublet,\n"
          "frequency_sd_hz, sigma_sd_per_s: Cramer-Rao standard deviations, merged: 1 for one partial\n"
          "standing for a doublet too close to resolve, whose damping is the beating envelope's),\n"
          "'f0_hz' and 'B'. With string={'L':..,'mu':..,'d':..[,'T':..]} also 'fit' (B, delta_ve, Q_te_inv,\n"
          "...), 'mode_table' for `modes` modes (measured where reliable, models elsewhere) and\n"
          "'mode_table_y' (the weaker partials of resolved doublets, 'mode_table' elsewhere).\n"
          "Raises InputError (a ValueError) for a signal that cannot be analysed.");
}

}  // namespace fretbuzz::python
