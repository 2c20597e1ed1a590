// `fretbuzz estimate RECORDING --out DIR`: the partials of a freely decaying string by
// ESPRIT, the string's models fitted to them, and a mode table and case text for `run`.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "../Commands.hpp"
#include "../PythonScript.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/analysis/EstimateOutput.hpp"
#include "fretbuzz/analysis/ModalEstimation.hpp"
#include "fretbuzz/analysis/ModelFit.hpp"
#include "fretbuzz/model/SteelWire.hpp"
#include "fretbuzz/analysis/Recording.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/output/OutputDirectory.hpp"

namespace fretbuzz::cli {

namespace {

struct EstimateArguments {
    std::string recording;
    std::string out;
    std::optional<double> f0;
    std::optional<std::size_t> modes;
    std::vector<double> band;
    std::size_t channel = 1;
    std::optional<std::string> case_name;
    std::optional<double> length, tension, density, diameter;
    int polarisations = 1;
    std::size_t partials_per_band = 5;
    std::size_t max_partial = 200;
    bool fit_air = false;
    bool no_whitening = false;
    bool no_plots = false;
    bool quiet = false;
};

double required(const std::optional<double>& value, const std::string& option, const std::string& what) {
    if (!value) throw InputError(option + " is missing: " + what + " (or give --case with a [string] section)");
    return *value;
}

int estimate_command(const EstimateArguments& a) {
    // Everything that can reject the input runs before the output directory exists, the
    // recording first: a missing file is the first thing to hear about.
    const Recording recording = read_recording(a.recording, a.channel);
    std::optional<Case> base;
    if (a.case_name) base = load_case(*a.case_name);
    StringParameters string;
    string.length_m = base && !a.length ? base->string.length_m : required(a.length, "--L", "string length in m");
    string.linear_density =
        base && !a.density ? base->string.linear_density : required(a.density, "--mu", "linear density in kg/m");
    string.tension_n = a.tension ? a.tension : base ? std::optional(base->string.tension_n) : std::nullopt;
    std::optional<double> diameter = a.diameter;
    if (!diameter && a.case_name) diameter = case_diameter(*a.case_name);
    if (!diameter) {
        diameter = SteelWire::of_linear_density(string.linear_density).diameter_m;
        if (!a.quiet)
            std::cerr << "fretbuzz: note: no --d and none in the case: d = " << *diameter * 1e3
                      << " mm assumed (a steel string of mu = " << string.linear_density << " kg/m)\n";
    }
    string.diameter_m = *diameter;
    if (a.polarisations != 1 && a.polarisations != 2)
        throw InputError(out_of_range_message("--polarisations", a.polarisations, "must be 1 or 2"));
    const bool two_polarisations = a.polarisations == 2;
    const std::size_t mode_count = a.modes.value_or(base ? base->mode_count() : 100);
    if (mode_count < 1 || mode_count > 100000)
        throw InputError(out_of_range_message("--modes", static_cast<double>(mode_count), "must be in [1, 100000]"));
    if (!a.band.empty() && a.band.size() != 2) throw InputError("--band: give two frequencies, LOW HIGH in Hz");

    EstimationOptions options;
    options.f0_hz = a.f0;
    if (a.band.size() == 2) {
        options.band_low_hz = a.band[0];
        options.band_high_hz = a.band[1];
    }
    if (a.partials_per_band < 1 || a.partials_per_band > 20)
        throw InputError(out_of_range_message("--partials-per-band", static_cast<double>(a.partials_per_band),
                                              "must be in [1, 20]"));
    options.partials_per_band = a.partials_per_band;
    options.max_partials = a.max_partial;
    options.whiten = !a.no_whitening;
    options.full_scale = 1.0;
    const ModalEstimate estimate = ModalEstimation(options).estimate(recording.samples, recording.rate_hz);
    const StringFit fit = ModelFit(string, a.fit_air).fit(estimate);
    const ModeTable table = ModelFit::mode_table(fit, estimate, mode_count);

    OutputDirectory out(a.out);
    write_partials_csv(out.staged("partials.csv"), estimate);
    write_mode_table_csv(out.staged(kModeTableFile), table);
    if (two_polarisations) write_mode_table_csv(out.staged(kModeTableYFile), ModelFit::y_mode_table(table, estimate));
    write_model_curves_csv(out.staged("model_curves.csv"), fit,
                           std::max<std::size_t>(mode_count, estimate.partials.back().mode));
    write_fit_json(out.staged("fit.json"), estimate, fit, table);
    {
        const auto path = out.staged("case-snippet.toml");
        std::ofstream snippet(path);
        snippet << case_snippet(fit, mode_count, string.diameter_m, two_polarisations);
        if (!snippet) throw std::runtime_error("cannot write " + path.string());
    }
    if (a.case_name) {
        const auto path = out.staged("case.toml");
        write_estimated_case(path, *a.case_name, fit, mode_count, string.diameter_m, two_polarisations,
                             [&out](const std::string& name) { return out.staged(name); });
        // The rest of the base case must fit the estimated string (a --L shorter than the
        // case's puts its positions off the string): nothing is written otherwise.
        try {
            load_case(path.string());
        } catch (const InputError& e) {
            throw InputError("the case written from --case " + *a.case_name + " is not valid: " + e.what() +
                             " (give --L, --T and --mu that fit that case, or leave them to it)");
        }
    }
    out.commit();

    std::size_t reliable = 0, doublets = 0, merged = 0;
    for (const EstimatedPartial& p : estimate.partials) {
        reliable += p.reliable ? 1 : 0;
        doublets += p.polarisation == 2 ? 1 : 0;
        merged += p.merged ? 1 : 0;
    }
    if (!a.quiet && merged > 0)
        std::cerr << "fretbuzz: note: " << merged << " mode(s) ring as a doublet too close to resolve in this record "
                  << "(merged = 1 in partials.csv): each is reported as one partial whose damping is the beating "
                     "envelope's, not either polarisation's; a longer or cleaner recording resolves them\n";
    if (!a.quiet)
        std::cerr << "fretbuzz: " << estimate.partials.size() << " partials (" << reliable << " reliable; "
                  << doublets << " modes with both polarisations, " << merged << " merged) in " << estimate.bands
                  << " bands; f0 = " << fit.frequency.f0_hz << " Hz, B = "
                  << fit.frequency.inharmonicity << " (rms " << fit.frequency.rms_cents << " cents); delta_ve = "
                  << fit.damping.parameters.viscoelastic_loss << ", 1/Q_te = "
                  << fit.damping.parameters.thermoelastic_inverse_q << " (sigma rms error "
                  << 100.0 * fit.damping.rms_relative_error << " %); outputs in " << out.path().string() << "\n";
    if (!a.no_plots) {
        std::vector<std::string> arguments{"--estimate", out.path().string()};
        if (a.quiet) arguments.emplace_back("--quiet");
        if (run_python_script(plot_script(), arguments) != 0)
            std::cerr << "fretbuzz: warning: the estimate plot was not drawn (numpy and matplotlib are needed)\n";
    }
    return 0;
}

}  // namespace

void add_estimate_command(CLI::App& app, Action& action) {
    auto a = std::make_shared<EstimateArguments>();
    CLI::App* cmd = app.add_subcommand(
        "estimate", "Partials of a recorded free decay by ESPRIT, fitted string models, a mode table and case text");
    cmd->add_option("recording", a->recording, "Audio file (WAV, FLAC, ...; any rate and depth)")->required();
    cmd->add_option("--out", a->out, "Output directory")->required();
    cmd->add_option("--f0", a->f0, "Fundamental in Hz (default: found from the spectrum)");
    cmd->add_option("--modes", a->modes, "Modes in the mode table (default: the --case's, else 100)");
    cmd->add_option("--band", a->band, "Analysed range LOW HIGH in Hz (default 20 to min(0.45 fs, 20000))")
        ->expected(2);
    cmd->add_option("--channel", a->channel, "Channel of a multichannel file, from 1")->capture_default_str();
    cmd->add_option("--case", a->case_name,
                    "Built-in case or .toml whose string (L, T, mu) to use; case.toml is written from it");
    cmd->add_option("--L", a->length, "String length, m");
    cmd->add_option("--T", a->tension, "Tension, N (default: from f0)");
    cmd->add_option("--mu", a->density, "Linear density, kg/m");
    cmd->add_option("--d", a->diameter,
                    "Outer diameter, m (air damping; default: the --case's, else a steel string's of that mu)");
    cmd->add_option("--polarisations", a->polarisations,
                    "2: also write modes_y.csv (each mode's weaker partial) and a two-polarisation case")
        ->capture_default_str();
    cmd->add_option("--partials-per-band", a->partials_per_band, "Partials kept per analysis band")
        ->capture_default_str();
    cmd->add_option("--max-partial", a->max_partial, "Highest mode number searched")->capture_default_str();
    cmd->add_flag("--fit-air", a->fit_air, "Fit the air term's equivalent diameter too (default: d)");
    cmd->add_flag("--no-whitening", a->no_whitening, "Do not whiten the noise in each band");
    cmd->add_flag("--no-plots", a->no_plots, "Do not draw estimate.png");
    cmd->add_flag("-q,--quiet", a->quiet, "Print nothing on success");
    cmd->callback([a, &action] { action = [a] { return estimate_command(*a); }; });
}

}  // namespace fretbuzz::cli
