// `fretbuzz convergence`: run a case at several sampling rates (or penalty stiffnesses),
// compare each with a reference run, print the table, write convergence.csv and a plot.
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "../Commands.hpp"
#include "../PythonScript.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/output/OutputDirectory.hpp"
#include "fretbuzz/sweep/Convergence.hpp"
#include "fretbuzz/sweep/ConvergenceOutput.hpp"

namespace fretbuzz::cli {

namespace {

struct ConvergenceArguments {
    std::string case_name;
    std::vector<double> fs, stiffness;
    std::optional<double> reference_fs, reference_stiffness, duration, observe, compare_rate;
    double window = 0.0;
    double threshold = 0.1;
    unsigned jobs = 0;
    bool lossless = false;
    std::string out = "fretbuzz-convergence";
};

ConvergenceStudy make_study(const ConvergenceArguments& a) {
    ConvergenceStudy study;
    study.base = load_case(a.case_name);
    if (a.lossless) study.base.make_lossless();
    if (!a.stiffness.empty()) {
        study.parameter = ConvergenceParameter::stiffness;
        if (a.fs.size() > 1)
            throw InputError("--fs: a stiffness study (--K) runs at one sampling rate; give a single --fs");
        if (a.reference_fs) throw InputError("--reference-fs: only for a sampling-rate study (without --K)");
        if (a.fs.size() == 1) study.base.run.sample_rate_hz = a.fs.front();
        study.values = a.stiffness;
        study.reference = a.reference_stiffness;
    } else {
        if (a.reference_stiffness) throw InputError("--reference-K: only for a stiffness study (with --K)");
        study.values = a.fs;
        study.reference = a.reference_fs;
    }
    study.window_s = a.window;
    study.duration_s = a.duration;
    study.observation_point_m = a.observe;
    study.threshold = a.threshold;
    study.comparison_rate_hz = a.compare_rate;
    study.jobs = a.jobs;
    return study;
}

// The log-log plot, drawn by the plotting module from the CSV; an empty string when drawn,
// else why not (the CSV is complete either way).
std::string plot_convergence(const ConvergenceReport& r, const std::filesystem::path& csv,
                             const std::filesystem::path& png) {
    std::ostringstream title, threshold;
    title << r.case_name << ": error against the reference " << parameter_name(r.parameter) << " = " << r.reference
          << ", window " << r.window_s << " s";
    threshold << r.threshold;
    try {
        const int status = run_python_script(plot_script(), {"--convergence", csv.string(), png.string(), title.str(),
                                                             threshold.str(), parameter_name(r.parameter)});
        if (status == 0 && std::filesystem::exists(png)) return "";
        return "the plotting module failed (is python3-matplotlib installed?)";
    } catch (const std::runtime_error& e) {
        return e.what();
    }
}

int convergence_command(const ConvergenceArguments& a) {
    const ConvergenceStudy study = make_study(a);
    OutputDirectory out(a.out);
    const ConvergenceReport report = run_convergence(study);
    const auto csv = out.staged("convergence.csv");
    write_convergence_csv(report, csv);
    const std::string plot_problem = plot_convergence(report, csv, out.staged("convergence.png"));
    out.commit();
    std::cout << format_convergence_table(report);
    std::cerr << "fretbuzz: outputs in " << out.path().string() << (plot_problem.empty() ? "" : " (no plot: " + plot_problem + ")")
              << "\n";
    return 0;
}

}  // namespace

void add_convergence_command(CLI::App& app, Action& action) {
    auto args = std::make_shared<ConvergenceArguments>();
    CLI::App* cmd = app.add_subcommand(
        "convergence", "Relative L2 error of the observation signal against a reference run, over several fs or K");
    cmd->add_option("case", args->case_name, "Built-in case name or path to a .toml file")->required();
    cmd->add_option("--fs", args->fs, "Sampling rates to study (Hz, comma-separated); with --K: the one rate used")
        ->delimiter(',');
    cmd->add_option("--reference-fs", args->reference_fs, "Reference sampling rate (default: the largest --fs)");
    cmd->add_option("--K", args->stiffness, "Penalty stiffnesses to study (comma-separated), towards the rigid limit")
        ->delimiter(',');
    cmd->add_option("--reference-K", args->reference_stiffness, "Reference stiffness (default: the largest --K)");
    cmd->add_option("--window", args->window, "Errors over [0, window] s (the paper: 0.3)")->required();
    cmd->add_option("--duration", args->duration, "Simulated duration in s (default: the window)");
    cmd->add_option("--observe", args->observe, "Observation point x in m (default: the case's first)");
    cmd->add_option("--threshold", args->threshold, "Relative error to meet (the paper: 0.1)")->capture_default_str();
    cmd->add_option("--compare-rate", args->compare_rate, "Rate (Hz) at which signals are compared; must divide every fs");
    cmd->add_option("--jobs", args->jobs, "Runs at a time (default: the hardware's threads)");
    cmd->add_flag("--lossless", args->lossless, "Remove all damping (sigma_j = 0)");
    cmd->add_option("--out", args->out, "Output directory")->capture_default_str();
    cmd->callback([args, &action] { action = [args] { return convergence_command(*args); }; });
}

}  // namespace fretbuzz::cli
