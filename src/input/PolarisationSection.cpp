// The keys of the second polarisation: [string] polarisations, [polarisation_y] (the y mode
// table: scale factors on the z table, or a measured table of its own), excitation.angle,
// contact.friction and contact.friction_velocity, audio.pickup_angle.
#include <sstream>

#include "CaseSections.hpp"
#include "fretbuzz/Error.hpp"

namespace fretbuzz {

namespace {

ModeTable read_y_table(TomlSection& s, const DataSource& data, std::size_t mode_count) {
    for (std::string_view other : {"frequency_scale", "damping_scale"})
        if (s.has(other))
            throw InputError(s.key_path("table") + " gives every y mode; it cannot be combined with " +
                             s.key_path(other));
    const CsvTable table = read_section_table(s, "table", data, 3);
    const std::string where = s.key_path("table") + " = \"" + s.text("table") + "\"";
    if (table.row_count() != mode_count) {
        std::ostringstream msg;
        msg << where << " lists " << table.row_count() << " modes but string.modes = " << mode_count
            << ": both polarisations share one modal basis and need the same mode count";
        throw InputError(msg.str());
    }
    ModeTable y;
    for (std::size_t j = 0; j < mode_count; ++j) {
        const auto& row = table.rows[j];
        if (row[0] != static_cast<double>(j + 1))
            throw InputError(where + ": data row " + std::to_string(j + 1) + " must be mode " + std::to_string(j + 1));
        y.frequency_hz.push_back(row[1]);
        y.sigma_per_s.push_back(row[2]);
        y.source.push_back(ModeSource::measured);
    }
    try {
        y.validate();
    } catch (const InputError& e) {
        throw InputError(where + ": " + e.what());
    }
    return y;
}

}  // namespace

void read_polarisation_count(TomlSection& string_section, Case& c) {
    c.polarisation.count = static_cast<int>(string_section.optional_count("polarisations", 1, 2).value_or(1));
}

void read_polarisation_y_section(TomlSection& s, const DataSource& data, Case& c) {
    // One polarisation has no y modes: the table would be ignored.
    if (!c.two_polarisations())
        throw InputError("[" + s.path() + "] describes the second polarisation, but string.polarisations = " +
                         std::to_string(c.polarisation.count) +
                         ": set string.polarisations = 2, or leave the table out");
    if (const auto modes = s.optional_count("modes", 1, 1000000); modes && *modes != c.mode_count())
        throw InputError(out_of_range_message(s.key_path("modes"), static_cast<double>(*modes),
                                              "must equal string.modes = " + std::to_string(c.mode_count()) +
                                                  " (both polarisations share one modal basis)"));
    if (s.has("table")) {
        c.polarisation.table = read_y_table(s, data, c.mode_count());
    } else {
        c.polarisation.frequency_scale = s.optional_positive("frequency_scale").value_or(1.0);
        c.polarisation.damping_scale = s.optional_non_negative("damping_scale").value_or(1.0);
    }
    s.finish();
}

void read_excitation_angle(TomlSection& excitation, Case& c) {
    c.polarisation.angle_deg = excitation.optional_number("angle").value_or(0.0);
}

void read_friction(TomlSection& contact, Case& c) {
    c.polarisation.friction = contact.optional_non_negative("friction").value_or(0.0);
    c.polarisation.friction_velocity = contact.optional_positive("friction_velocity").value_or(1e-3);
}

void read_pickup_angle(TomlSection& audio, Case& c) {
    if (const auto angle = audio.optional_number("pickup_angle")) {
        c.polarisation.pickup_angle_deg = *angle;
        c.polarisation.pickup_angle_given = true;
    }
}

}  // namespace fretbuzz
