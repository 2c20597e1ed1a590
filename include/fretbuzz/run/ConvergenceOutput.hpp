#pragma once
// What a convergence study leaves behind: a table for people, a CSV for programs, and a
// log-log plot (drawn by matplotlib; the script is carried inside the library).
#include <filesystem>
#include <string>

#include "fretbuzz/run/Convergence.hpp"

namespace fretbuzz {

// Header lines, one row per level, and the verdict against the threshold.
std::string format_convergence_table(const ConvergenceReport& report);

// Columns: parameter,value,relative_error,observed_order,meets_threshold,wall_seconds
// (observed_order empty on the coarsest level).
void write_convergence_csv(const ConvergenceReport& report, const std::filesystem::path& path);

struct PlotOutcome {
    bool written = false;
    std::string message;  // why not, when it was not
};

// Draws error against level from the CSV with `python` (e.g. /usr/bin/python3) and matplotlib.
PlotOutcome plot_convergence(const ConvergenceReport& report, const std::filesystem::path& csv,
                             const std::filesystem::path& png, const std::string& python = "/usr/bin/python3");

}  // namespace fretbuzz
