#include "fretbuzz/analysis/EstimateOutput.hpp"

#include <cmath>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>
#include <toml++/toml.h>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/TextFile.hpp"
#include "fretbuzz/model/DampingModel.hpp"
#include "fretbuzz/model/FrequencyModel.hpp"

namespace fretbuzz {

namespace {


std::ofstream open_for_writing(const std::filesystem::path& path) {
    std::ofstream out(path);
    if (!out) throw std::runtime_error("cannot write " + path.string());
    out << std::setprecision(17);
    return out;
}

void close_checked(std::ofstream& out, const std::filesystem::path& path) {
    out.close();
    if (!out) throw std::runtime_error("writing " + path.string() + " failed");
}

// The base case as TOML: a built-in case's text or the file's.
toml::table parse_base_case(const std::string& base) {
    const std::string text =
        is_builtin_case(base) ? builtin_case_text(base) : read_text_file(base, "--case", kMaxCaseFileBytes);
    try {
        return toml::parse(text, base);
    } catch (const toml::parse_error& e) {
        throw InputError("--case " + base + ": " + std::string(e.description()));
    }
}

// Copies every data file the case names (string values ending in .csv) next to the new case.
void copy_data_files(toml::table& table, const DataSource& data, const std::string& base,
                     const std::function<std::filesystem::path(const std::string&)>& stage) {
    for (auto&& [key, node] : table) {
        if (auto* sub = node.as_table()) {
            copy_data_files(*sub, data, base, stage);
        } else if (auto* text = node.as_string()) {
            const std::string value = text->get();
            if (!value.ends_with(".csv")) continue;
            const std::string name = std::filesystem::path(value).filename().string();
            std::ofstream out = open_for_writing(stage(name));
            out << data.read(value, std::string(key.str()));
            close_checked(out, stage(name));
            *text = name;
        }
    }
}

}  // namespace

void write_partials_csv(const std::filesystem::path& path, const ModalEstimate& estimate) {
    std::ofstream out = open_for_writing(path);
    out << "# mode,frequency_hz,sigma_per_s,quality_factor,amplitude,phase_rad,snr_db,band,reliable,polarisation,"
           "frequency_sd_hz,sigma_sd_per_s,merged\n";
    for (const EstimatedPartial& p : estimate.partials)
        out << p.mode << ',' << p.frequency_hz << ',' << p.sigma_per_s << ',' << quality_factor(p.frequency_hz, p.sigma_per_s)
            << ',' << p.amplitude << ',' << p.phase_rad << ',' << p.snr_db << ',' << p.band << ','
            << (p.reliable ? 1 : 0) << ',' << p.polarisation << ',' << p.frequency_sd_hz << ',' << p.sigma_sd_per_s
            << ',' << (p.merged ? 1 : 0) << '\n';
    close_checked(out, path);
}

void write_mode_table_csv(const std::filesystem::path& path, const ModeTable& table) {
    std::ofstream out = open_for_writing(path);
    out << "# mode,frequency_hz,sigma_per_s,source\n";
    for (std::size_t j = 0; j < table.size(); ++j)
        out << j + 1 << ',' << table.frequency_hz[j] << ',' << table.sigma_per_s[j] << ',' << to_string(table.source[j])
            << '\n';
    close_checked(out, path);
}

void write_model_curves_csv(const std::filesystem::path& path, const StringFit& fit, std::size_t mode_count) {
    const FrequencyModel frequency(fit.string, fit.frequency.inharmonicity);
    const DampingModel damping(fit.string, fit.damping.parameters);
    std::ofstream out = open_for_writing(path);
    out << "# mode,harmonic_hz,frequency_hz,sigma_per_s\n";
    for (std::size_t j = 1; j <= mode_count; ++j) {
        const double nu = frequency.frequency_hz(j);
        out << j << ',' << fit.string.harmonic_frequency_hz(j) << ',' << nu << ',' << damping.sigma_per_s(j, nu) << '\n';
    }
    close_checked(out, path);
}

void write_fit_json(const std::filesystem::path& path, const ModalEstimate& estimate, const StringFit& fit,
                    const ModeTable& table) {
    std::size_t reliable = 0, measured = 0, measured_up_to = 0, doublets = 0, merged = 0;
    for (const EstimatedPartial& p : estimate.partials) {
        reliable += p.reliable ? 1 : 0;
        doublets += p.polarisation == 2 ? 1 : 0;
        merged += p.merged ? 1 : 0;
    }
    for (std::size_t j = 0; j < table.size(); ++j)
        if (table.source[j] == ModeSource::measured) ++measured, measured_up_to = j + 1;
    const DampingParameters& d = fit.damping.parameters;
    const nlohmann::ordered_json json = {
        {"recording",
         {{"rate_hz", estimate.rate_hz},
          {"decay_start_s", estimate.start_s},
          {"decay_duration_s", estimate.duration_s},
          {"band_hz", {estimate.band_low_hz, estimate.band_high_hz}},
          {"bands", estimate.bands}}},
        {"poles", {{"in_kept_ranges", estimate.poles}, {"rejected", estimate.rejected_poles}}},
        {"partials",
         {{"found", estimate.partials.size()}, {"reliable", reliable}, {"doublets", doublets}, {"merged", merged}}},
        {"frequency_model",
         {{"f0_hz", fit.frequency.f0_hz},
          {"B", fit.frequency.inharmonicity},
          {"rms_cents", fit.frequency.rms_cents},
          {"max_cents", fit.frequency.max_cents},
          {"modes_fitted", fit.frequency.points}}},
        {"string",
         {{"L_m", fit.string.length_m},
          {"T_n", fit.string.tension_n},
          {"T_given_n", fit.given_tension_n},
          {"mu_kg_per_m", fit.string.linear_density},
          {"E_core_I_core_n_m2", d.core_bending_stiffness}}},
        {"damping_model",
         {{"delta_ve", d.viscoelastic_loss},
          {"Q_te_inv", d.thermoelastic_inverse_q},
          {"d_eq_m", d.equivalent_diameter_m},
          {"air_fitted", fit.damping.air_fitted},
          {"sigma_rms_relative_error", fit.damping.rms_relative_error},
          {"sigma_max_relative_error", fit.damping.max_relative_error},
          {"modes_fitted", fit.damping.points}}},
        {"mode_table", {{"modes", table.size()}, {"measured", measured}, {"measured_up_to", measured_up_to}}}};
    std::ofstream out = open_for_writing(path);
    out << json.dump(2) << '\n';
    close_checked(out, path);
}

std::string case_snippet(const StringFit& fit, std::size_t mode_count, double diameter_m, bool two_polarisations) {
    std::ostringstream s;
    s << std::setprecision(10);
    s << "# From `fretbuzz estimate`: T puts the fitted f0 = " << fit.frequency.f0_hz << " Hz at c/(2L)";
    if (fit.given_tension_n > 0.0) s << " (given T = " << fit.given_tension_n << " N)";
    s << ".\n[string]\nL = " << fit.string.length_m << "\nT = " << fit.string.tension_n
      << "\nmu = " << fit.string.linear_density << "\nd = " << diameter_m << "\nB = " << fit.frequency.inharmonicity
      << "\nmodes = " << mode_count << (two_polarisations ? "\npolarisations = 2" : "") << "\n\n"
      << "# Measured where reliable, the fitted models elsewhere (source column).\n"
      << "# Fitted damping model: delta_ve = " << fit.damping.parameters.viscoelastic_loss
      << ", Q_te_inv = " << fit.damping.parameters.thermoelastic_inverse_q
      << ", d_eq = " << fit.damping.parameters.equivalent_diameter_m << " m.\n"
      << "[modes]\ntable = \"" << kModeTableFile << "\"\n";
    if (two_polarisations)
        s << "\n# y: the weaker partial of each resolved doublet, the z mode elsewhere.\n"
          << "[polarisation_y]\ntable = \"" << kModeTableYFile << "\"\n";
    return s.str();
}

std::optional<double> case_diameter(const std::string& base) {
    const toml::table root = parse_base_case(base);
    if (auto d = root["string"]["d"].value<double>()) return d;
    return root["modes"]["damping"]["d_eq"].value<double>();
}

void write_estimated_case(const std::filesystem::path& path, const std::string& base, const StringFit& fit,
                          std::size_t mode_count, double diameter_m, bool two_polarisations,
                          const std::function<std::filesystem::path(const std::string&)>& stage) {
    const DataSource data = is_builtin_case(base) ? DataSource::builtin()
                                                  : DataSource::directory(std::filesystem::path(base).parent_path());
    toml::table root = parse_base_case(base);
    root.erase("modes");
    root.erase("polarisation_y");
    copy_data_files(root, data, base, stage);
    toml::table string = root["string"].as_table() ? *root["string"].as_table() : toml::table{};
    for (const char* key : {"E_core", "E_core_I_core", "d_core"}) string.erase(key);
    string.insert_or_assign("L", fit.string.length_m);
    string.insert_or_assign("T", fit.string.tension_n);
    string.insert_or_assign("mu", fit.string.linear_density);
    string.insert_or_assign("d", diameter_m);
    string.insert_or_assign("B", fit.frequency.inharmonicity);
    string.insert_or_assign("modes", static_cast<int64_t>(mode_count));
    if (two_polarisations) string.insert_or_assign("polarisations", int64_t{2});
    root.insert_or_assign("string", std::move(string));
    root.insert_or_assign("modes", toml::table{{"table", kModeTableFile}});
    if (two_polarisations) root.insert_or_assign("polarisation_y", toml::table{{"table", kModeTableYFile}});
    if (auto name = root["name"].value<std::string>()) root.insert_or_assign("name", *name + "-estimated");
    std::ofstream out = open_for_writing(path);
    out << "# " << base << " with the string estimated by `fretbuzz estimate` (see fit.json)\n" << root << '\n';
    close_checked(out, path);
}

}  // namespace fretbuzz
