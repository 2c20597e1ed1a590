#pragma once
// The files `fretbuzz estimate` writes: the partials found, the mode table (measured where
// reliable, models elsewhere, with a source column), the fitted models and their
// quality, the model curves for the plots, and the case text that uses the table.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "fretbuzz/analysis/ModalEstimation.hpp"
#include "fretbuzz/analysis/ModelFit.hpp"
#include "fretbuzz/model/ModeTable.hpp"

namespace fretbuzz {

inline constexpr const char* kModeTableFile = "modes.csv";
inline constexpr const char* kModeTableYFile = "modes_y.csv";  // the y polarisation's, when asked for

// mode,frequency_hz,sigma_per_s,quality_factor,amplitude,phase_rad,snr_db,band,reliable,polarisation,
// frequency_sd_hz,sigma_sd_per_s (Cramer-Rao standard deviations),merged
void write_partials_csv(const std::filesystem::path& path, const ModalEstimate& estimate);
// mode,frequency_hz,sigma_per_s,source: what [modes] table = "modes.csv" reads.
void write_mode_table_csv(const std::filesystem::path& path, const ModeTable& table);
// mode,harmonic_hz,frequency_hz,sigma_per_s of the fitted models, modes 1..mode_count.
void write_model_curves_csv(const std::filesystem::path& path, const StringFit& fit, std::size_t mode_count);
void write_fit_json(const std::filesystem::path& path, const ModalEstimate& estimate, const StringFit& fit,
                    const ModeTable& table);
// [string] and [modes] sections for the estimated string (and [polarisation_y], reading
// kModeTableYFile, with two polarisations).
std::string case_snippet(const StringFit& fit, std::size_t mode_count, double diameter_m, bool two_polarisations);
// The outer diameter a case gives its string: string.d, else modes.damping.d_eq.
std::optional<double> case_diameter(const std::string& base);
// A whole case: `base` (a built-in case name or .toml path) with its [string] and [modes]
// (and [polarisation_y]) replaced by the estimated ones; other data files it names are
// copied next to it through `stage` (which returns where to write a file of that name).
void write_estimated_case(const std::filesystem::path& path, const std::string& base, const StringFit& fit,
                          std::size_t mode_count, double diameter_m, bool two_polarisations,
                          const std::function<std::filesystem::path(const std::string&)>& stage);

}  // namespace fretbuzz
