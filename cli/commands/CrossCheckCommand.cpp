// `fretbuzz cross-check`: the modal scheme against the independent finite-difference scheme
// on the slapping-string problem, over a list of grids; prints the table and writes CSVs.
#include <cstddef>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "../Commands.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/output/OutputDirectory.hpp"
#include "fretbuzz/reference/CrossCheck.hpp"

namespace fretbuzz::cli {

namespace {

struct CrossCheckArguments {
    std::vector<std::size_t> intervals{80, 160, 320, 640};
    double stiffness = 1e6;
    double bending_stiffness = 0.0;
    double duration = 2.0;
    std::string out = "fretbuzz-cross-check";
};

void write_levels(const reference::CrossCheckReport& r, const std::filesystem::path& path) {
    std::ofstream out(path);
    out << std::setprecision(17) << "N,dt,fd_to_reference,modal_to_reference,fd_to_modal,fd_energy_drift\n";
    for (const auto& l : r.levels)
        out << l.intervals << ',' << l.dt << ',' << l.fd_to_reference << ',' << l.modal_to_reference << ','
            << l.fd_to_modal << ',' << l.fd_energy_drift << '\n';
    if (!out) throw InputError("--out: cannot write " + path.string());
}

void write_signals(const reference::CrossCheckReport& r, const std::filesystem::path& path) {
    std::ofstream out(path);
    out << std::setprecision(17) << "t,reference";
    for (const auto& l : r.levels) out << ",fd_N" << l.intervals;
    out << '\n';
    for (std::size_t k = 0; k < r.reference.values.size(); ++k) {
        out << static_cast<double>(k) / r.reference.rate_hz << ',' << r.reference.values[k];
        for (const auto& l : r.levels) out << ',' << (k < l.fd_signal.values.size() ? l.fd_signal.values[k] : 0.0);
        out << '\n';
    }
    if (!out) throw InputError("--out: cannot write " + path.string());
}

int cross_check_command(const CrossCheckArguments& a) {
    reference::CrossCheckStudy study;
    study.intervals = a.intervals;
    study.problem.contact_stiffness = a.stiffness;
    study.problem.bending_stiffness = a.bending_stiffness;
    study.duration_s = a.duration;
    for (std::size_t n : a.intervals)
        if (n < 4 || n % 4 != 0)
            throw InputError("--N = " + std::to_string(n) + " is out of range: must be a multiple of 4 (>= 4), so that "
                             "the observation point x = 0.25 is a grid point");
    OutputDirectory out(a.out);
    const reference::CrossCheckReport r = reference::run_cross_check(study);
    write_levels(r, out.staged("cross_check.csv"));
    write_signals(r, out.staged("cross_check_signals.csv"));
    out.commit();
    std::cout << "u(0.25, t) over [0, " << a.duration << "] s, relative L2 differences (reference: modal, "
              << study.reference_modes << " modes, fs = " << study.reference_sample_rate_hz << " Hz)\n\n"
              << std::setw(6) << "N" << std::setw(12) << "dt" << std::setw(14) << "FD-ref" << std::setw(14)
              << "modal-ref" << std::setw(14) << "FD-modal" << std::setw(14) << "FD drift\n";
    for (const auto& l : r.levels)
        std::cout << std::setw(6) << l.intervals << std::setw(12) << std::setprecision(4) << l.dt << std::scientific
                  << std::setprecision(3) << std::setw(14) << l.fd_to_reference << std::setw(14) << l.modal_to_reference
                  << std::setw(14) << l.fd_to_modal << std::setw(13) << l.fd_energy_drift << std::defaultfloat << "\n";
    return 0;
}

}  // namespace

void add_cross_check_command(CLI::App& app, Action& action) {
    auto args = std::make_shared<CrossCheckArguments>();
    CLI::App* cmd = app.add_subcommand(
        "cross-check", "Modal scheme against an independent finite-difference scheme (string slapping a flat obstacle)");
    cmd->add_option("--N", args->intervals, "Finite-difference grids (intervals, multiples of 4, comma-separated)")
        ->delimiter(',')
        ->capture_default_str();
    cmd->add_option("--K", args->stiffness, "Penalty stiffness")->capture_default_str();
    cmd->add_option("--EI", args->bending_stiffness, "Bending stiffness (weakly stiff string)")->capture_default_str();
    cmd->add_option("--duration", args->duration, "Simulated duration in s (the period is 2 s)")->capture_default_str();
    cmd->add_option("--out", args->out, "Output directory")->capture_default_str();
    cmd->callback([args, &action] { action = [args] { return cross_check_command(*args); }; });
}

}  // namespace fretbuzz::cli
