// [modes]: per-mode frequencies and dampings. Either one table for every mode
// (table = "file.csv"), or measurements for some modes (measured = "file.csv") with
// the frequency and damping models of [modes.frequency] and [modes.damping] for the rest.
#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>

#include "CaseSections.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/model/DampingModel.hpp"
#include "fretbuzz/model/ModeTableAssembly.hpp"
#include "fretbuzz/model/WavenumberDamping.hpp"

namespace fretbuzz {

namespace {

void read_full_table(TomlSection& section, const DataSource& data, std::size_t mode_count, Case& c) {
    for (std::string_view other : {"measured", "measured_up_to", "nut_mobility", "frequency", "damping"})
        if (section.has(other))
            throw InputError(section.key_path("table") + " gives every mode; it cannot be combined with " +
                             section.key_path(other) + " (use " + section.key_path("measured") +
                             " to mix measurements and models)");
    const CsvTable table = read_section_table(section, "table", data, 3);
    const std::string file = section.text("table");
    if (table.row_count() < mode_count) {
        std::ostringstream msg;
        msg << section.key_path("table") << " = \"" << file << "\" lists " << table.row_count()
            << " modes but string.modes = " << mode_count << " are requested";
        throw InputError(msg.str());
    }
    ModeTable& modes = c.modes;
    for (std::size_t j = 0; j < mode_count; ++j) {
        const auto& row = table.rows[j];
        if (row[0] != static_cast<double>(j + 1)) {
            std::ostringstream msg;
            msg << section.key_path("table") << " = \"" << file << "\": data row " << j + 1 << " is mode " << row[0]
                << "; modes must be listed 1, 2, 3, ... in order";
            throw InputError(msg.str());
        }
        modes.frequency_hz.push_back(row[1]);
        modes.sigma_per_s.push_back(row[2]);
        // A `source` column (as `fretbuzz estimate` and `fretbuzz modes` write it) is kept.
        const std::string& label = table.labels[j];
        if (!label.empty() && label != "measured" && label != "model")
            throw InputError(section.key_path("table") + " = \"" + file + "\": data row " + std::to_string(j + 1) +
                             " has source '" + label + "'; it must be \"measured\" or \"model\"");
        modes.source.push_back(label == "model" ? ModeSource::model : ModeSource::measured);
    }
    modes.validate();
}

std::vector<MeasuredMode> read_measured(TomlSection& section, const DataSource& data) {
    const CsvTable table = read_section_table(section, "measured", data, 3);
    const auto up_to = section.optional_count("measured_up_to", 1, kMaxModes);
    const std::string where = section.key_path("measured") + " = \"" + section.text("measured") + "\"";
    std::vector<MeasuredMode> measured;
    std::vector<bool> seen;
    for (std::size_t r = 0; r < table.row_count(); ++r) {
        const auto& row = table.rows[r];
        const std::string at = where + " data row " + std::to_string(r + 1);
        const bool whole = row[0] == std::floor(row[0]);
        if (!(whole && row[0] >= 1.0 && row[0] <= static_cast<double>(kMaxModes)))
            throw InputError(out_of_range_message(at + " mode", row[0], "must be a whole number >= 1"));
        const auto mode = static_cast<std::size_t>(row[0]);
        if (up_to && mode > *up_to) continue;
        require_positive(at + " frequency_hz", row[1]);
        require_non_negative(at + " sigma_per_s", row[2]);
        if (seen.size() < mode) seen.resize(mode, false);
        if (seen[mode - 1]) throw InputError(at + ": mode " + std::to_string(mode) + " is listed twice");
        seen[mode - 1] = true;
        measured.push_back({mode, row[1], row[2]});
    }
    return measured;
}

NutMobility read_nut_mobility(TomlSection& section, const DataSource& data) {
    const CsvTable table = read_section_table(section, "nut_mobility", data, 3);
    return NutMobility(table.column(0), table.column(1), table.column(2),
                       section.key_path("nut_mobility") + " = \"" + section.text("nut_mobility") + "\"");
}

// B for the inharmonic model: given, or from the core's bending stiffness.
double inharmonicity(TomlSection& s, const StringDescription& string, const TautString& taut) {
    if (string.inharmonicity) return *string.inharmonicity;
    if (string.core_bending_stiffness) return taut.inharmonicity_for(*string.core_bending_stiffness);
    throw InputError(s.key_path("model") +
                     " = \"inharmonic\" needs string.B, string.E_core_I_core or string.E_core with string.d_core");
}

StiffnessFormula read_formula(TomlSection& s) {
    const std::string formula = s.optional_text("formula").value_or("exact");
    if (formula == "exact") return StiffnessFormula::exact;
    if (formula == "first-order") return StiffnessFormula::first_order;
    throw InputError(s.key_path("formula") + " = \"" + formula +
                     "\": must be \"exact\" (nu_0j sqrt(1 + B j^2), the default) or \"first-order\" "
                     "(nu_0j (1 + B j^2 / 2), the paper's formula, for B j^2 <= 0.1)");
}

// The first-order formula beyond its range is allowed (the paper's cases use it) but said.
void warn_first_order_range(const TomlSection& s, const FrequencyModel& model, std::size_t mode_count, Case& c) {
    const double b = model.inharmonicity();
    const double top = b * static_cast<double>(mode_count) * static_cast<double>(mode_count);
    if (model.formula() != StiffnessFormula::first_order || top <= FrequencyModel::kFirstOrderLimit) return;
    const auto from = static_cast<std::size_t>(std::ceil(std::sqrt(FrequencyModel::kFirstOrderLimit / b)));
    std::ostringstream msg;
    msg.precision(4);
    msg << s.key_path("formula") << " = \"first-order\" is used beyond its range: B j^2 > "
        << FrequencyModel::kFirstOrderLimit << " from mode " << from << " on, and B j^2 = " << top << " at mode "
        << mode_count << ", where nu_j is " << (1.0 + top / 2.0) / std::sqrt(1.0 + top)
        << " times the exact stiff-string value (use formula = \"exact\")";
    c.warnings.push_back(msg.str());
}

FrequencyModel read_frequency_model(TomlSection s, const StringDescription& string, const TautString& taut,
                                    const NutMobility& nut, Case& c) {
    const std::string model = s.text("model");
    std::optional<FrequencyModel> result;
    if (model == "harmonic") {
        result.emplace(taut, 0.0);  // an ideal string: no stiffness, rigid ends
    } else if (model == "inharmonic") {
        result.emplace(taut, inharmonicity(s, string, taut), nut, read_formula(s));
        warn_first_order_range(s, *result, string.mode_count, c);
    } else {
        throw InputError(s.key_path("model") + " = \"" + model + "\": must be one of \"inharmonic\", \"harmonic\"");
    }
    s.finish();
    return *result;
}

// E_core I_core for the viscoelastic losses: given, or from B (B = pi^2 EI / (T L^2)).
double core_stiffness(TomlSection& s, const StringDescription& string, const TautString& taut) {
    if (string.core_bending_stiffness) return *string.core_bending_stiffness;
    if (string.inharmonicity) return taut.bending_stiffness_for(*string.inharmonicity);
    throw InputError(s.key_path("delta_ve") +
                     " > 0 needs string.E_core_I_core, string.E_core with string.d_core, or string.B");
}

// sigma_j = eta0 + eta2 (j pi / L)^2.
std::unique_ptr<ModalDamping> read_damping_law(TomlSection& s, const TautString& taut) {
    const double eta0 = s.non_negative("eta0");
    const double eta2 = s.non_negative("eta2");
    s.finish();
    return std::make_unique<WavenumberDamping>(taut.length_m, eta0, eta2);
}

std::unique_ptr<ModalDamping> read_damping_model(TomlSection s, const StringDescription& string,
                                                 const TautString& taut, const NutMobility& nut) {
    const std::string model = s.text("model");
    if (model == "none") {
        s.finish();
        return nullptr;
    }
    if (model == "law") return read_damping_law(s, taut);
    if (model != "physical")
        throw InputError(s.key_path("model") + " = \"" + model +
                         "\": must be one of \"physical\", \"law\" (sigma_j = eta0 + eta2 (j pi / L)^2), \"none\"");
    DampingParameters p;
    p.air_viscosity = s.optional_positive("eta_air").value_or(p.air_viscosity);
    p.air_density = s.optional_positive("rho_air").value_or(p.air_density);
    if (auto d_eq = s.optional_positive("d_eq"))
        p.equivalent_diameter_m = *d_eq;
    else if (string.diameter_m)
        p.equivalent_diameter_m = *string.diameter_m;
    else
        throw InputError(s.key_path("d_eq") + " is missing (required by the air losses when string.d is not given)");
    p.viscoelastic_loss = s.optional_non_negative("delta_ve").value_or(0.0);
    if (p.viscoelastic_loss > 1.0)
        throw InputError(out_of_range_message(s.key_path("delta_ve"), p.viscoelastic_loss, "must be in [0, 1]"));
    if (p.viscoelastic_loss > 0.0) p.core_bending_stiffness = core_stiffness(s, string, taut);
    p.thermoelastic_inverse_q = s.optional_non_negative("Q_te_inv").value_or(0.0);
    if (p.thermoelastic_inverse_q > 1.0)
        throw InputError(out_of_range_message(s.key_path("Q_te_inv"), p.thermoelastic_inverse_q, "must be in [0, 1]"));
    s.finish();
    return std::make_unique<DampingModel>(taut, p, nut);
}

bool every_mode_measured(const std::vector<MeasuredMode>& measured, std::size_t mode_count) {
    std::vector<bool> covered(mode_count, false);
    for (const MeasuredMode& m : measured)
        if (m.mode <= mode_count) covered[m.mode - 1] = true;
    return std::find(covered.begin(), covered.end(), false) == covered.end();
}

}  // namespace

void read_modes_section(TomlSection& section, const DataSource& data, const StringDescription& string,
                        bool lossless, Case& c) {
    const std::size_t mode_count = string.mode_count;
    if (string.ideal)
        for (std::string_view key : {"table", "frequency", "nut_mobility"})
            if (section.has(key))
                throw InputError(section.key_path(key) + " cannot be combined with string.ideal = true, which fixes "
                                 "every frequency at nu_j = j c / (2L) (remove one of them)");
    if (section.has("table")) {
        read_full_table(section, data, mode_count, c);
        return;
    }
    if (section.has("measured_up_to") && !section.has("measured"))
        throw InputError(section.key_path("measured_up_to") + " needs " + section.key_path("measured"));
    const std::vector<MeasuredMode> measured =
        section.has("measured") ? read_measured(section, data) : std::vector<MeasuredMode>{};
    const NutMobility nut = section.has("nut_mobility") ? read_nut_mobility(section, data) : NutMobility{};
    const TautString taut{c.string.length_m, c.string.tension_n, c.string.linear_density};

    std::optional<FrequencyModel> frequency;
    if (string.ideal) frequency.emplace(taut, 0.0);
    if (auto s = section.optional_section("frequency")) frequency = read_frequency_model(*s, string, taut, nut, c);
    std::unique_ptr<ModalDamping> damping;
    const bool has_damping = section.has("damping");
    if (auto s = section.optional_section("damping")) damping = read_damping_model(*s, string, taut, nut);

    if (!every_mode_measured(measured, mode_count)) {
        const std::string why = " (required: not every one of the string.modes = " + std::to_string(mode_count) +
                                " modes is in " + section.key_path("measured") + "; or give " +
                                section.key_path("table") + ")";
        if (!frequency) throw InputError(section.key_path("frequency") + " is missing" + why);
        if (!has_damping && !lossless)
            throw InputError(section.key_path("damping") + " is missing" + why +
                             ": give model = \"physical\", \"law\" (eta0, eta2) or \"none\" (a lossless "
                             "string), or set run.lossless = true");
    }
    try {
        c.modes = assemble_mode_table(mode_count, measured, frequency ? &*frequency : nullptr, damping.get());
    } catch (const InputError& e) {
        throw InputError(section.path() + ": " + e.what());
    }
}

}  // namespace fretbuzz
