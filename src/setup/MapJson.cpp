// map.json: the buzz map with everything needed to draw it (the HTML page's template and
// the studio read it): the instrument's geometry string by string, the settings, each note's
// verdict, the comparison with an earlier map and the advice.
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "MillimetreText.hpp"
#include "fretbuzz/setup/MapFiles.hpp"

namespace fretbuzz {

namespace {

using Json = nlohmann::ordered_json;

Json number(double v) { return std::isfinite(v) ? Json(v) : Json(); }

Json numbers(const std::vector<double>& values) {
    Json a = Json::array();
    for (double v : values) a.push_back(number(v));
    return a;
}

Json fret(int f) {
    if (f == kNoFret) return Json();
    return f == kBoard ? Json("board") : Json(f);
}

Json verdict(const NoteVerdict& v) {
    Json plucks = Json::array();
    for (double db : v.pluck_db) plucks.push_back(number(db));
    Json touches = Json::array();
    for (double t : v.pluck_touch_s) touches.push_back(number(t));
    // clean_up_to is infinite when no search size made the note buzz: "at least" kCleanUpToCap.
    const bool unbounded = std::isinf(v.clean_up_to);
    return Json{{"string", v.string_name},     {"fret", v.fret},
                {"strength", v.strength},      {"status", v.status},
                {"verdict", v.verdict},
                {"buzz_fraction", v.buzz_fraction},
                {"buzz_fraction_low", number(v.buzz_fraction_low)},
                {"buzz_fraction_high", number(v.buzz_fraction_high)},
                {"buzz_dB", number(v.buzz_db)},
                {"buzz_fret", fret(v.buzz_fret)},   {"touch_fraction", v.touch_fraction},
                {"plucks", v.plucks},          {"pluck_dB", plucks},
                {"first_touch_s", number(v.first_touch_s)}, {"pluck_touch_s", touches},
                {"clean_up_to", unbounded ? Json(kCleanUpToCap) : number(v.clean_up_to)},
                {"clean_up_to_at_least", unbounded},
                {"clean_up_to_value", number(v.clean_up_to_value)},
                {"unit", v.unit},
                {"stiffness_sensitive", v.stiffness_sensitive},
                {"clearance_mm", number(v.clearance_m * 1e3)}, {"audio", v.audio}};
}

}  // namespace

void write_map_json(const std::filesystem::path& path, const Instrument& instrument, const MapDocument& d) {
    Json strings = Json::array();
    for (const StringGeometry& g : describe_geometry(instrument))
        strings.push_back(Json{{"name", g.name},
                               {"scale_length_m", g.scale_length_m},
                               {"frequency_hz", g.frequency_hz},
                               {"tension_n", g.tension_n},
                               {"linear_density", g.linear_density},
                               {"inharmonicity", g.inharmonicity},
                               {"gauge_m", number(g.gauge_m)},
                               {"tension_source", g.tension_source},
                               {"nut_height_m", g.nut_height_m},
                               {"saddle_height_m", g.saddle_height_m},
                               {"nut_gap_m", g.nut_gap_m},
                               {"action12_m", number(g.action12_m)},
                               {"relief_gap_m", g.relief_gap_m},
                               {"relief_fret", g.relief_fret},
                               {"nut_axial_m", g.nut_axial_m},
                               {"lateral_nut_m", g.lateral_nut_m},
                               {"lateral_bridge_m", g.lateral_bridge_m},
                               {"fret_x_m", numbers(g.fret_x_m)},
                               {"fret_top_m", numbers(g.fret_top_m)},
                               {"fret_line_m", numbers(g.fret_line_m)},
                               {"gap_m", numbers(g.gap_m)},
                               {"surface_x_m", numbers(g.surface_x_m)},
                               {"surface_z_m", numbers(g.surface_z_m)}});
    Json attacks = Json::array();
    for (const Attack& a : d.attacks)
        attacks.push_back(Json{{"label", a.label},
                               {"gesture", gesture_name(a.gesture)},
                               {"size", a.shown_size()},
                               {"unit", a.unit()},
                               {"angle_deg", a.where.angle_deg},
                               {"from_bridge_m", a.where.from_bridge_m},
                               {"width_m", a.where.width_m}});
    const BenchSettings& b = instrument.bench;
    const AttackSettings& s = instrument.attack;
    Json notes = Json::array();
    for (const NoteVerdict& v : d.notes) notes.push_back(verdict(v));
    Json comparison = Json::array();
    for (const NoteChange& c : d.comparison) {
        Json row = verdict(c.now);
        row["change"] = c.change;
        row["reason"] = c.reason;
        row["before"] = c.change == "new" ? Json() : verdict(c.before);
        comparison.push_back(row);
    }
    Json dress;
    if (!d.dress_json.empty()) {
        dress = Json::parse(d.dress_json);
        Json after = Json::array();
        for (const NoteVerdict& v : d.dressed_notes) after.push_back(verdict(v));
        dress["after"] = after;
    }
    Json doc{{"instrument", instrument.name},
             {"units", units_name(instrument.units)},
             {"description", instrument.description},
             {"command", d.command},
             {"changes", d.changes},
             {"frets", instrument.neck.fret_count},
             {"fret_height_m", instrument.neck.fret_height_m},
             {"stopped_notes", d.finger ? "finger" : "stand-in"},
             {"settings",
              Json{{"fs_hz", b.sample_rate_hz},
                   {"duration_s", b.duration_s},
                   {"grid_step_m", b.grid_step_m},
                   {"output_rate_hz", b.output_rate_hz},
                   {"observe_from_bridge_m", b.observe_from_bridge_m},
                   {"listening_level_dB_SPL", b.listening_level_db_spl},
                   {"audible_dB", b.audible_db},
                   {"fret_friction", b.fret_friction},
                   {"attack_style", s.style},
                   {"ensemble", s.ensemble},
                   {"position_spread_m", s.position_spread_m},
                   {"angle_spread_deg", s.angle_spread_deg},
                   {"strength_spread", s.strength_spread},
                   {"seed", s.seed}}},
             {"attacks", attacks},
             {"calibration", d.player_file.empty() ? Json()
                                                   : Json{{"file", d.player_file}, {"attack_scale", d.attack_scale}}},
             {"strings", strings},
             {"notes", notes},
             {"compared_with", d.compared_with},
             {"comparison", comparison},
             {"advice", d.advice_json.empty() ? Json() : Json::parse(d.advice_json)},
             {"dress", dress},
             {"wall_seconds", d.wall_seconds}};
    std::ofstream out(path, std::ios::binary);
    out << doc.dump(1) << "\n";
    out.close();
    if (!out) throw std::runtime_error("cannot write " + path.string());
}

}  // namespace fretbuzz
