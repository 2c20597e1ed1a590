#pragma once
// What a convergence study leaves behind: a table for people and a CSV for programs (the
// command line draws its log-log plot from the CSV with the plotting module).
#include <filesystem>
#include <string>

#include "fretbuzz/sweep/Convergence.hpp"

namespace fretbuzz {

// Header lines, one row per level, and the verdict against the threshold.
std::string format_convergence_table(const ConvergenceReport& report);

// Columns: parameter,value,relative_error,observed_order,meets_threshold,wall_seconds
// (observed_order empty on the coarsest level).
void write_convergence_csv(const ConvergenceReport& report, const std::filesystem::path& path);

}  // namespace fretbuzz
