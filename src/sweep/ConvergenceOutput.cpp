#include "fretbuzz/sweep/ConvergenceOutput.hpp"

#include <cstdio>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "fretbuzz/Error.hpp"

namespace fretbuzz {

namespace {

// Sampling rates as whole hertz, stiffnesses in scientific notation.
std::string format_level(ConvergenceParameter parameter, double value) {
    std::ostringstream out;
    if (parameter == ConvergenceParameter::sample_rate) out << std::fixed << std::setprecision(0) << value;
    else out << std::setprecision(4) << value;
    return out.str();
}

}  // namespace

std::string format_convergence_table(const ConvergenceReport& r) {
    const std::string name = parameter_name(r.parameter);
    const bool rates = r.parameter == ConvergenceParameter::sample_rate;
    const std::string unit = rates ? " Hz" : "";
    std::ostringstream out;
    out << std::setprecision(6);
    out << "convergence of " << r.case_name << " in " << name << ": reference " << name << " = "
        << format_level(r.parameter, r.reference) << unit;
    if (!rates) out << " at fs = " << format_level(ConvergenceParameter::sample_rate, r.fixed_sample_rate_hz) << " Hz";
    out << "\nrelative L2 error of u(x = " << r.observation_point_m << " m) over [0, " << r.window_s << "] s ("
        << r.samples_compared << " samples at " << r.comparison_rate_hz << " Hz), " << r.parallel_runs
        << " runs in parallel\n\n";
    out << std::setw(14) << (rates ? name + " [Hz]" : name) << std::setw(16) << "rel. L2 error" << std::setw(10) << "order"
        << std::setw(10) << ("< " + [&] {
               std::ostringstream t;
               t << r.threshold;
               return t.str();
           }())
        << std::setw(12) << "wall [s]" << "\n";
    for (const ConvergenceLevel& level : r.levels) {
        std::ostringstream order;
        if (level.observed_order) order << std::fixed << std::setprecision(2) << *level.observed_order;
        else order << "-";
        out << std::setw(14) << format_level(r.parameter, level.value) << std::setw(16) << std::scientific << std::setprecision(3)
            << level.relative_error << std::defaultfloat << std::setprecision(6) << std::setw(10) << order.str()
            << std::setw(10) << (level.meets_threshold ? "yes" : "no") << std::setw(12) << std::fixed
            << std::setprecision(2) << level.wall_seconds << std::defaultfloat << std::setprecision(6) << "\n";
    }
    out << std::setw(14) << format_level(r.parameter, r.reference) << std::setw(16) << "(reference)" << std::setw(10) << "" << std::setw(10) << ""
        << std::setw(12) << std::fixed << std::setprecision(2) << r.reference_wall_seconds << std::defaultfloat
        << std::setprecision(6) << "\n\n";
    if (r.threshold_met_from)
        out << "criterion (relative L2 error < " << r.threshold << ") met from " << name << " = " << format_level(r.parameter, *r.threshold_met_from)
            << unit << " on\n";
    else
        out << "criterion (relative L2 error < " << r.threshold << ") not met by the finest level\n";
    return out.str();
}

void write_convergence_csv(const ConvergenceReport& r, const std::filesystem::path& path) {
    std::ofstream out(path);
    if (!out) throw InputError("--out: cannot write " + path.string());
    out << std::setprecision(17);
    out << "parameter,value,relative_error,observed_order,meets_threshold,wall_seconds\n";
    for (const ConvergenceLevel& level : r.levels) {
        out << parameter_name(r.parameter) << ',' << level.value << ',' << level.relative_error << ',';
        if (level.observed_order) out << *level.observed_order;
        out << ',' << (level.meets_threshold ? 1 : 0) << ',' << level.wall_seconds << '\n';
    }
    if (!out) throw InputError("--out: cannot write " + path.string());
}

}  // namespace fretbuzz
