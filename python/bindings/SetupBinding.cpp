// The set-up bench from Python: instruments (built-in or from a file or text), their
// geometry, what-ifs, the buzz map with a callback per finished note, one note with its
// audio and contacts, the comparison of two maps and the advice. python/fretbuzz/setup_bench.py
// (fretbuzz.Bench, fretbuzz.setup) turns these into pandas DataFrames; its docstrings are
// the contract for the studio.
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <cmath>
#include <string>
#include <tuple>

#include "BackgroundRun.hpp"
#include "Bindings.hpp"
#include "Conversions.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/InstrumentFile.hpp"
#include "fretbuzz/input/InstrumentUnits.hpp"
#include "fretbuzz/setup/Advice.hpp"
#include "fretbuzz/analysis/Recording.hpp"
#include "fretbuzz/output/AudioWriter.hpp"
#include "fretbuzz/setup/BuzzMap.hpp"
#include "fretbuzz/setup/Calibration.hpp"
#include "fretbuzz/setup/FretDress.hpp"
#include "fretbuzz/setup/InstrumentGeometry.hpp"
#include "fretbuzz/setup/MapFiles.hpp"
#include "fretbuzz/setup/WhatIf.hpp"

namespace fretbuzz::python {

namespace py = pybind11;

namespace {

py::object number(double v) { return std::isfinite(v) ? py::object(py::float_(v)) : py::object(py::none()); }

py::object fret_value(int f) {
    if (f == kNoFret) return py::none();
    return f == kBoard ? py::object(py::str("board")) : py::object(py::int_(f));
}

py::dict verdict_dict(const NoteVerdict& v) {
    py::dict d;
    d["string"] = v.string_name;
    d["fret"] = v.fret;
    d["strength"] = v.strength;
    d["verdict"] = v.verdict;
    d["buzz_fraction"] = v.buzz_fraction;
    d["buzz_fraction_low"] = number(v.buzz_fraction_low);
    d["buzz_fraction_high"] = number(v.buzz_fraction_high);
    d["buzz_dB"] = number(v.buzz_db);
    d["buzz_fret"] = fret_value(v.buzz_fret);
    d["touch_fraction"] = v.touch_fraction;
    d["plucks"] = v.plucks;
    // inf: clean at every size searched, up to kCleanUpToCap times the attack
    d["clean_up_to"] = std::isnan(v.clean_up_to) ? py::object(py::none()) : py::object(py::float_(v.clean_up_to));
    d["clean_up_to_value"] =
        std::isnan(v.clean_up_to_value) ? py::object(py::none()) : py::object(py::float_(v.clean_up_to_value));
    d["unit"] = v.unit;
    d["stiffness_sensitive"] = v.stiffness_sensitive;
    d["status"] = v.status;
    d["clearance_mm"] = number(v.clearance_m * 1e3);
    py::list plucks;
    for (double db : v.pluck_db) plucks.append(number(db));
    d["pluck_dB"] = plucks;
    py::list touches;
    for (double t : v.pluck_touch_s) touches.append(number(t));
    d["first_touch_s"] = number(v.first_touch_s);
    d["pluck_touch_s"] = touches;
    d["audio"] = v.audio;
    d["deciding_pluck"] = v.deciding_pluck;
    return d;
}

NoteVerdict verdict_from(py::handle row, std::size_t index) {
    const std::string at = "map row " + std::to_string(index);
    if (!py::isinstance<py::dict>(row)) throw py::type_error(at + ": expected a dict (a map's row), got " + type_name(row));
    const py::dict d = py::reinterpret_borrow<py::dict>(row);
    const auto field = [&](const char* key) -> py::handle {
        if (!d.contains(key)) throw InputError(at + ": no " + key);
        return d[key];
    };
    const auto fraction = [&](const char* key) {
        const double v = to_number(field(key), at + ": " + key);
        if (!(v >= 0.0 && v <= 1.0)) throw InputError(out_of_range_message(at + ": " + key, v, "must be in [0, 1]"));
        return v;
    };
    constexpr long long kMost = 1 << 20;
    NoteVerdict v;
    v.string_name = to_text(field("string"), at + ": string");
    v.fret = static_cast<std::size_t>(to_whole(field("fret"), at + ": fret", 0, kMost));
    v.strength = to_text(field("strength"), at + ": strength");
    v.verdict = d.contains("verdict") ? to_text(d["verdict"], at + ": verdict") : "";
    v.buzz_fraction = fraction("buzz_fraction");
    if (d.contains("clean_up_to") && !d["clean_up_to"].is_none())
        v.clean_up_to = to_number(d["clean_up_to"], at + ": clean_up_to");
    v.buzz_db = field("buzz_dB").is_none() ? NoteVerdict::nan : to_number(d["buzz_dB"], at + ": buzz_dB");
    const py::handle buzz_fret = field("buzz_fret");
    if (buzz_fret.is_none())
        v.buzz_fret = kNoFret;
    else if (py::isinstance<py::str>(buzz_fret) && buzz_fret.cast<std::string>() == "board")
        v.buzz_fret = kBoard;
    else
        v.buzz_fret = static_cast<int>(to_whole(buzz_fret, at + ": buzz_fret (or \"board\", or None)", 0, kMost));
    v.touch_fraction = d.contains("touch_fraction") ? fraction("touch_fraction") : 0.0;
    v.plucks = d.contains("plucks") ? static_cast<std::size_t>(to_whole(d["plucks"], at + ": plucks", 0, kMost)) : 0;
    v.status = d.contains("status") ? to_text(d["status"], at + ": status") : "ok";
    return v;
}

std::vector<NoteVerdict> verdicts_from(const py::iterable& rows) {
    std::vector<NoteVerdict> out;
    for (py::handle row : rows) out.push_back(verdict_from(row, out.size()));
    return out;
}

double millimetres(py::handle value, const std::string& name) {
    if (py::isinstance<py::str>(value)) return parse_quantity_or(value.cast<std::string>(), Quantity::length, "mm", name);
    return to_number(value, name) * 1e-3;
}

// The library's checks are those of `fretbuzz setup`; their messages name the options as the
// command line spells them. Here they name the arguments as Python spells them.
using OptionNames = std::vector<std::pair<std::string, std::string>>;
const OptionNames kSetupNames = {
    {"--relief-change", "relief_change"}, {"--nut-change ", "nut_change "}, {"--saddle-change ", "saddle_change "},
    {"--relief", "relief"}, {"--action12 ", "action12 "}, {"--action ", "action "}, {"--nut ", "nut "}, {"--saddle ", "saddle "},
    {"--truss-rod-turns", "truss_rod_turns"}, {"--saddle-turns ", "saddle_turns "},
    {"--fret-offset ", "fret_offsets "}, {"--frets", "frets"}, {"--strings", "strings"},
    {"--strength", "strengths"}, {"--tune ", "tune "}, {"--set", "string_set"}};
const OptionNames kDressNames = {{"--dress-depth", "depth"}, {"--crown", "crown"}, {"--fall-away", "fall_away"}};

template <class F>
auto with_python_names(F&& f, const OptionNames& names = kSetupNames) {
    try {
        return f();
    } catch (const InputError& e) {
        std::string message = e.what();
        for (const auto& [from, to] : names)
            for (std::size_t at = message.find(from); at != std::string::npos; at = message.find(from, at + to.size()))
                message.replace(at, from.size(), to);
        throw InputError(message);
    }
}

// The what-ifs as Python gives them; InputError messages name the Python argument.
Instrument changed(const Instrument& instrument, const py::object& relief, const py::dict& action12,
                   const py::dict& nut, const py::dict& saddle, const py::dict& fret_offsets, const py::dict& tune,
                   const py::object& string_set, const py::object& relief_change, const py::dict& action,
                   const py::dict& nut_change, const py::dict& saddle_change, const py::object& truss_rod_turns,
                   const py::dict& saddle_turns) {
    SetupChange change;
    // Turns: a number, or text as the command line takes it ("1/4", "-1/2 turn").
    const auto turns = [](py::handle value, const std::string& name, double most) {
        return py::isinstance<py::str>(value) ? screw_turns(value.cast<std::string>(), name, most) : to_number(value, name);
    };
    if (!truss_rod_turns.is_none()) change.truss_rod_turns = turns(truss_rod_turns, "truss_rod_turns", kMostTrussRodTurns);
    for (const auto& [key, value] : saddle_turns) {
        const std::string string = to_text(key, "saddle_turns (a string's name)");
        instrument.string_index(string);
        change.saddle_turns.emplace_back(string, turns(value, "saddle_turns['" + string + "']", kMostSaddleTurns));
    }
    if (!string_set.is_none()) change.string_set = to_text(string_set, "string_set");
    for (const auto& [key, value] : tune) {
        const std::string string = to_text(key, "tune (a string's name)");
        instrument.string_index(string);
        const std::string name = "tune['" + string + "']";
        change.pitch_hz.emplace_back(string, py::isinstance<py::str>(value)
                                                 ? parse_quantity_or(value.cast<std::string>(), Quantity::frequency, "Hz", name)
                                                 : to_number(value, name));
    }
    if (!relief.is_none()) change.relief_m = millimetres(relief, "relief");
    if (!relief_change.is_none()) change.relief_change_m = millimetres(relief_change, "relief_change");
    const auto ends = [&](const py::dict& given, const std::string& name,
                          std::vector<std::pair<std::string, double>>& into) {
        for (const auto& [key, value] : given) {
            const std::string string = to_text(key, name + " (a string's name)");
            instrument.string_index(string);
            into.emplace_back(string, millimetres(value, name + "['" + string + "']"));
        }
    };
    std::vector<std::pair<std::string, double>> at12;
    ends(action12, "action12", at12);
    for (const auto& [string, gap] : at12) change.action_m.push_back({string, 12, gap});
    for (const auto& [key, per_string] : action) {
        // Out of range, the library's message names the frets there are.
        const auto fret = static_cast<std::size_t>(to_whole(key, "action (a key: a fret's number)", 0, 1 << 20));
        if (!py::isinstance<py::dict>(per_string))
            throw InputError("action[" + std::to_string(fret) + "] must be a dict {string: length}, e.g. "
                             "action={17: {'E': '3/32 in'}}");
        std::vector<std::pair<std::string, double>> gaps;
        ends(per_string.cast<py::dict>(), "action[" + std::to_string(fret) + "]", gaps);
        for (const auto& [string, gap] : gaps) change.action_m.push_back({string, fret, gap});
    }
    ends(nut, "nut", change.nut_m);
    ends(saddle, "saddle", change.saddle_m);
    ends(nut_change, "nut_change", change.nut_change_m);
    ends(saddle_change, "saddle_change", change.saddle_change_m);
    for (const auto& [key, value] : fret_offsets) {
        FretChange f;
        // Out of range, the library's message names the frets there are.
        f.fret = static_cast<std::size_t>(to_whole(key, "fret_offsets (a key: a fret's number)", 0, 1 << 20));
        const std::string name = "fret_offsets[" + std::to_string(f.fret) + "]";
        if (!(py::isinstance<py::str>(value) && value.cast<std::string>() == "level")) f.by_m = millimetres(value, name);
        change.frets.push_back(f);
    }
    return with_python_names([&] { return apply_change(instrument, change); });
}

py::list geometry(const Instrument& instrument) {
    py::list strings;
    for (const StringGeometry& g : describe_geometry(instrument)) {
        py::dict d;
        d["name"] = g.name;
        d["scale_length_m"] = g.scale_length_m;
        d["frequency_hz"] = g.frequency_hz;
        d["tension_n"] = g.tension_n;
        d["linear_density"] = g.linear_density;
        d["bending_stiffness"] = g.bending_stiffness;
        d["inharmonicity"] = g.inharmonicity;
        d["gauge_m"] = g.gauge_m;
        d["tension_source"] = g.tension_source;
        d["nut_height_m"] = g.nut_height_m;
        d["saddle_height_m"] = g.saddle_height_m;
        d["nut_gap_m"] = g.nut_gap_m;
        d["action12_m"] = number(g.action12_m);
        d["relief_gap_m"] = g.relief_gap_m;
        d["relief_fret"] = g.relief_fret;
        d["nut_axial_m"] = g.nut_axial_m;
        d["lateral_nut_m"] = g.lateral_nut_m;
        d["lateral_bridge_m"] = g.lateral_bridge_m;
        d["fret_x_m"] = to_numpy(g.fret_x_m);
        d["fret_top_m"] = to_numpy(g.fret_top_m);
        d["fret_line_m"] = to_numpy(g.fret_line_m);
        d["gap_m"] = to_numpy(g.gap_m);
        d["surface_x_m"] = to_numpy(g.surface_x_m);
        d["surface_z_m"] = to_numpy(g.surface_z_m);
        strings.append(d);
    }
    return strings;
}

py::dict settings(const Instrument& i) {
    py::dict d;
    d["fs_hz"] = i.bench.sample_rate_hz;
    d["duration_s"] = i.bench.duration_s;
    d["grid_step_m"] = i.bench.grid_step_m;
    d["output_rate_hz"] = i.bench.output_rate_hz;
    d["observe_from_bridge_m"] = i.bench.observe_from_bridge_m;
    d["listening_level_dB_SPL"] = i.bench.listening_level_db_spl;
    d["audible_dB"] = i.bench.audible_db;
    d["fret_friction"] = i.bench.fret_friction;
    d["attack_style"] = i.attack.style;
    d["ensemble"] = i.attack.ensemble;
    d["position_spread_m"] = i.attack.position_spread_m;
    d["angle_spread_deg"] = i.attack.angle_spread_deg;
    d["strength_spread"] = i.attack.strength_spread;
    d["seed"] = i.attack.seed;
    d["stopped_modes"] = i.bench.pinned_stops ? "pinned" : "held";
    d["listen"] = i.bench.listen_through_rig ? "rig" : "pickup";
    d["partial_scatter_cents"] = i.bench.partial_scatter_cents;
    return d;
}

Instrument with_settings(const Instrument& instrument, const py::object& ensemble, const py::object& fs,
                         const py::object& duration, const py::object& listen, const py::object& partial_scatter) {
    Instrument i = instrument;
    if (!ensemble.is_none()) {
        i.attack.ensemble = static_cast<std::size_t>(to_whole(ensemble, "ensemble (the most plucks per note)", 1, 200));
    }
    if (!fs.is_none()) {
        const double v = to_number(fs, "fs (Hz, in [50000, 2e7])");
        if (!(v >= 5e4 && v <= 2e7)) throw InputError(out_of_range_message("fs (Hz)", v, "must be in [50000, 2e7]"));
        i.bench.sample_rate_hz = v;
    }
    if (!duration.is_none()) {
        const double v = to_number(duration, "duration (s, in [0.01, 5])");
        if (!(v >= 0.01 && v <= 5.0)) throw InputError(out_of_range_message("duration (s)", v, "must be in [0.01, 5]"));
        i.bench.duration_s = v;
    }
    if (!listen.is_none()) {
        if (!py::isinstance<py::str>(listen))
            throw py::type_error("listen: expected 'rig' or 'pickup', got " + type_name(listen));
        i.bench.listen_through_rig = listens_through_rig(listen.cast<std::string>(), "listen");
    }
    if (!partial_scatter.is_none())
        i.bench.partial_scatter_cents =
            checked_partial_scatter(to_number(partial_scatter, "partial_scatter (cents, in [0, 50])"), "partial_scatter");
    return i;
}

// The strings and frets of a call as Python gives them: lists, each entry counted once, a fret
// a whole number of the instrument's (any Python int: 2**64 is out of range, named as such).
std::vector<std::string> string_names(const py::handle& strings) { return to_text_list(strings, "strings"); }
std::vector<std::size_t> fret_numbers(const Instrument& instrument, const py::handle& frets) {
    return to_whole_list(frets, "frets", 0, static_cast<long long>(instrument.neck.fret_count));
}

// The attacks a call names, each size times the player's attack scale (a calibration's, as
// --player applies it; 1: the instrument's own attacks).
std::vector<Attack> player_attacks(const std::string& text, const Instrument& instrument, const std::string& name,
                                   double attack_scale) {
    checked_attack_scale("attack_scale", attack_scale, " (a calibration's attack_scale; 1: the attacks as they are)");
    std::vector<Attack> attacks = parse_attacks(text, instrument.attack, name);
    scale_attacks(attacks, attack_scale);
    return attacks;
}

MapRequest map_request(const Instrument& instrument, const std::string& strengths, const py::handle& strings,
                       const py::handle& frets, bool finger, unsigned jobs, double attack_scale) {
    MapRequest r;
    r.attacks = player_attacks(strengths, instrument, "strengths", attack_scale);
    for (const std::string& s : string_names(strings)) r.strings.push_back(instrument.string_index(s));
    r.frets = fret_numbers(instrument, frets);
    r.finger = finger;
    r.jobs = jobs;
    map_notes(instrument, r);  // checked before anything runs
    return r;
}

// play_map in the background (BackgroundRun): `progress` gets each finished note on this
// thread; a callback that raises stops the map and its exception propagates; Ctrl-C stops it
// with KeyboardInterrupt; `stop()` returning True stops it and returns the notes so far.
py::list run_map(const Instrument& instrument, const std::string& strengths, const py::object& strings,
                 const py::object& frets, bool finger, unsigned jobs, const std::string& audio_dir,
                 const py::object& progress, const py::object& stop, double attack_scale) {
    MapRequest request =
        with_python_names([&] { return map_request(instrument, strengths, strings, frets, finger, jobs, attack_scale); });
    request.audio_dir = audio_dir;
    BackgroundRun<std::tuple<NoteVerdict, std::size_t, std::size_t>> background;
    request.stop = [&background] { return background.stopping(); };
    request.on_note = [&](const NoteVerdict& v, std::size_t done, std::size_t total) { background.post({v, done, total}); };
    BuzzMapResult result;
    background.run([&] { result = play_map(instrument, request); },
                   [&](const auto& report) {
                       const auto& [v, done, total] = report;
                       if (!progress.is_none()) progress(verdict_dict(v), done, total);
                   },
                   [&] { return !stop.is_none() && stop().cast<bool>(); });
    py::list notes;
    for (const NoteVerdict& v : result.notes) notes.append(verdict_dict(v));
    return notes;
}

// The player's calibration in the background, as run_map: calibration.json's text.
std::string calibrate(const Instrument& instrument, const std::string& report, const std::string& source, bool finger,
                      unsigned jobs, const py::object& progress) {
    const std::vector<HeardNote> rows = parse_player_report(report, source, instrument, "report");
    CalibrationRequest request;
    request.finger = finger;
    request.jobs = jobs;
    BackgroundRun<std::tuple<NoteVerdict, std::size_t, std::size_t>> background;
    request.stop = [&background] { return background.stopping(); };
    request.on_note = [&](const NoteVerdict& v, std::size_t done, std::size_t total) { background.post({v, done, total}); };
    Calibration c;
    background.run([&] { c = calibrate_attack(instrument, rows, request); },
                   [&](const auto& report_of_note) {
                       const auto& [v, done, total] = report_of_note;
                       if (!progress.is_none()) progress(verdict_dict(v), done, total);
                   });
    return calibration_json(c, instrument, source);
}

py::dict record(const Instrument& instrument, const std::string& string, const py::object& fret_given,
                const std::string& strength, const py::object& member_given, bool finger, const std::string& wav,
                double attack_scale) {
    const std::size_t s = instrument.string_index(string);
    const auto fret = static_cast<std::size_t>(
        to_whole(fret_given, "fret", 0, static_cast<long long>(instrument.neck.fret_count)));
    const auto member = static_cast<std::size_t>(to_whole(
        member_given, "member (a pluck of the ensemble)", 0, static_cast<long long>(instrument.attack.ensemble) - 1));
    const std::vector<Attack> attacks = player_attacks(strength, instrument, "strength", attack_scale);
    if (attacks.size() != 1) throw InputError("strength " + strength + ": give one attack");
    // With a WAV: the pluck's sound as long as a map's note's (kNoteSoundSeconds).
    const PluckOutcome o = without_gil(
        [&] { return record_pluck(instrument, s, fret, attacks.front(), member, finger, wav, kNoteSoundSeconds); });
    if (!o.error.empty()) throw InputError(string + " fret " + std::to_string(fret) + " " + strength + ": " + o.error);
    py::dict d;
    d["touched"] = o.touched;
    d["heard"] = heard_to_buzz(o, instrument.bench.audible_db);  // as the verdicts count it
    d["buzz_dB"] = number(o.buzz_db);
    d["buzz_fret"] = fret_value(o.buzz_fret);
    d["first_contact_s"] = number(o.first_contact_s);
    d["peak_force_n"] = o.peak_force_n;
    d["signal"] = to_numpy(o.signal);
    d["signal_rate_hz"] = o.signal_rate_hz;
    d["audio"] = to_numpy(o.audio);
    d["audio_rate_hz"] = o.audio_rate_hz;
    py::list contacts;
    for (const ContactStretch& c : o.contacts) {
        py::dict row;
        row["time_s"] = c.time_s;
        row["impulse_n_s"] = c.impulse_n_s;
        row["peak_force_n"] = c.peak_force_n;
        row["fret"] = fret_value(c.fret);
        contacts.append(row);
    }
    d["contacts"] = contacts;
    return d;
}

// What the advice and the dress answer for, as Python gives it (messages name the arguments).
AdviceRequest advice_request(const Instrument& instrument, const std::string& strength, const py::handle& strings,
                             const py::handle& frets, const std::string& tolerate, bool finger, unsigned jobs,
                             double attack_scale) {
    AdviceRequest request;
    const std::vector<Attack> attacks = player_attacks(strength, instrument, "strength", attack_scale);
    if (attacks.size() != 1) throw InputError("strength " + strength + ": give one attack");
    request.attack = attacks.front();
    request.finger = finger;
    request.jobs = jobs;
    for (const std::string& s : string_names(strings)) request.strings.push_back(instrument.string_index(s));
    MapRequest check;
    check.frets = fret_numbers(instrument, frets);
    check.attacks = attacks;
    with_python_names([&] { return map_notes(instrument, check); });
    request.frets = check.frets;
    request.tolerate = tolerance_for(instrument, tolerate, "tolerate");
    return request;
}

// A map's rows as the advice and the dress take them: notes of this instrument, each row a
// verdict the bench could have given (the searches start from what the rows say).
std::vector<NoteVerdict> map_verdicts(const Instrument& instrument, const py::iterable& map) {
    std::vector<NoteVerdict> verdicts = verdicts_from(map);
    const std::size_t frets = instrument.neck.fret_count;
    for (std::size_t k = 0; k < verdicts.size(); ++k) {
        NoteVerdict& v = verdicts[k];
        const std::string at = "map row " + std::to_string(k) + ": ";
        try {
            v.string = instrument.string_index(v.string_name);
        } catch (const InputError& e) {
            throw InputError(at + e.what());
        }
        if (v.fret < instrument.neck.capo || v.fret > frets)
            throw InputError(out_of_range_message(at + "fret", static_cast<double>(v.fret),
                                                  "must be a fret of " + instrument.name + ", " +
                                                      std::to_string(instrument.neck.capo) + " to " + std::to_string(frets)));
        if (v.verdict != "clean" && v.verdict != "marginal" && v.verdict != "buzzes" && !v.verdict.empty())
            throw InputError(at + "verdict = '" + v.verdict.substr(0, 40) +
                             "': must be 'clean', 'marginal', 'buzzes' or empty (not played)");
        if (v.buzz_fret != kNoFret && v.buzz_fret != kBoard && static_cast<std::size_t>(v.buzz_fret) > frets)
            throw InputError(out_of_range_message(at + "buzz_fret", v.buzz_fret,
                                                  "must be a fret of " + instrument.name + " (0 to " +
                                                      std::to_string(frets) + "), \"board\" or None"));
        if (!(std::isnan(v.clean_up_to) || v.clean_up_to >= 0.0))
            throw InputError(out_of_range_message(at + "clean_up_to", v.clean_up_to, "must be >= 0 (inf: clean at every size)"));
        if (std::isfinite(v.buzz_db) && std::abs(v.buzz_db) > 1000.0)
            throw InputError(out_of_range_message(at + "buzz_dB", v.buzz_db, "must be in [-1000, 1000] dB (or None)"));
    }
    return verdicts;
}

// A search (the advice, the dress) in the background (BackgroundRun): Ctrl-C stops it at its
// next pluck; `progress(note, probes)` gets each note a probe plays, on this thread.
void search_in_background(AdviceRequest& request, const py::object& progress, const std::function<void()>& search) {
    BackgroundRun<std::tuple<NoteVerdict, std::size_t>> background;
    request.stop = [&background] { return background.stopping(); };
    if (!progress.is_none())
        request.on_note = [&background](const NoteVerdict& v, std::size_t probes) { background.post({v, probes}); };
    background.run(search, [&](const auto& report) { progress(verdict_dict(std::get<0>(report)), std::get<1>(report)); });
}

std::string advice(const Instrument& instrument, const py::iterable& map, const std::string& strength,
                   const py::object& strings, const py::object& frets, const std::string& tolerate, bool finger,
                   unsigned jobs, double attack_scale, const py::object& progress) {
    AdviceRequest request = advice_request(instrument, strength, strings, frets, tolerate, finger, jobs, attack_scale);
    const std::vector<NoteVerdict> verdicts = map_verdicts(instrument, map);
    std::string json;
    search_in_background(request, progress, [&] { json = advice_json(advise(instrument, verdicts, request)); });
    return json;
}

// What the dress is asked, checked whole before anything is played (a depth of 1e308 is
// refused at once, not after the map).
DressRequest dress_request(const Instrument& instrument, const std::string& strength, const py::handle& strings,
                           const py::handle& frets, const std::string& tolerate, const py::object& depth,
                           const py::object& crown, const py::object& fall_away, bool finger, unsigned jobs,
                           double attack_scale) {
    DressRequest request;
    request.play = advice_request(instrument, strength, strings, frets, tolerate, finger, jobs, attack_scale);
    if (!depth.is_none()) request.max_depth_m = millimetres(depth, "depth");
    if (!crown.is_none()) request.min_crown_m = millimetres(crown, "crown");
    if (!fall_away.is_none())
        request.fall_away_from = static_cast<std::size_t>(
            to_whole(fall_away, "fall_away (the fret the fall-away starts from)", 0, 1 << 20));
    with_python_names(
        [&] {
            check_dress_request(instrument, request);
            return true;
        },
        kDressNames);
    return request;
}

py::dict dress(const Instrument& instrument, const py::iterable& map, const std::string& strength,
               const py::object& strings, const py::object& frets, const std::string& tolerate,
               const py::object& depth, const py::object& crown, const py::object& fall_away, bool finger, unsigned jobs,
               double attack_scale, const py::object& progress) {
    DressRequest request =
        dress_request(instrument, strength, strings, frets, tolerate, depth, crown, fall_away, finger, jobs, attack_scale);
    const std::vector<NoteVerdict> verdicts = map_verdicts(instrument, map);
    DressResult result;
    search_in_background(request.play, progress, [&] {
        result = with_python_names([&] { return dress_frets(instrument, verdicts, request); }, kDressNames);
    });
    py::dict d = py::module_::import("json").attr("loads")(dress_json(result));
    py::list after;
    for (const NoteVerdict& v : result.after) after.append(verdict_dict(v));
    d["after"] = after;
    d["csv"] = dress_csv(result);
    d["text"] = dress_text(result);
    d["dressed"] = result.dressed;
    return d;
}

// A note's WAV as a small Ogg Vorbis file (the studio's report embeds its sounds so).
void compressed_audio(const std::string& wav, const std::string& out) {
    const Recording sound = read_recording(wav);
    without_gil([&] {
        write_compact_audio(out, sound.samples, sound.rate_hz);
        return true;
    });
}

}  // namespace

void bind_setup(py::module_& m) {
    py::class_<Instrument>(m, "Instrument",
                           "An instrument on the set-up bench (see fretbuzz.Bench and docs/instrument-format.md).")
        .def_readonly("name", &Instrument::name)
        .def_readonly("description", &Instrument::description)
        .def_readonly("source_text", &Instrument::source_text, "the instrument file it was read from")
        .def_property_readonly("strings",
                               [](const Instrument& i) {
                                   std::vector<std::string> names;
                                   for (const InstrumentString& s : i.strings) names.push_back(s.name);
                                   return names;
                               },
                               "the strings' names, in the file's order")
        .def_property_readonly("frets", [](const Instrument& i) { return i.neck.fret_count; })
        .def_property_readonly("settings", &settings, "how finely notes are simulated and how buzz is judged")
        .def_readonly("warnings", &Instrument::warnings, "what reading it found doubtful (e.g. a mass implausible for a gauge)")
        .def_property_readonly("units",
                               [](const Instrument& i) {
                                   return std::string(i.units == ShopUnits::mm                ? "mm"
                                                      : i.units == ShopUnits::sixty_fourths ? "64ths"
                                                                                            : "thousandths");
                               },
                               "the units its file gives the gaps in: 'mm', '64ths' (of an inch) or 'thousandths'")
        .def("geometry", &geometry,
             "The neck under each string: a list of dicts (see fretbuzz.Bench.geometry). InputError if a string "
             "would lie on a fret.")
        .def("with_settings", &with_settings, py::arg("ensemble") = py::none(), py::arg("fs") = py::none(),
             py::arg("duration") = py::none(), py::arg("listen") = py::none(), py::arg("partial_scatter") = py::none(),
             "A copy with these simulation settings (InputError if out of range).")
        .def("with_changes", &changed, py::arg("relief") = py::none(), py::arg("action12") = py::dict(),
             py::arg("nut") = py::dict(), py::arg("saddle") = py::dict(), py::arg("fret_offsets") = py::dict(),
             py::arg("tune") = py::dict(), py::arg("string_set") = py::none(), py::arg("relief_change") = py::none(),
             py::arg("action") = py::dict(), py::arg("nut_change") = py::dict(), py::arg("saddle_change") = py::dict(),
             py::arg("truss_rod_turns") = py::none(), py::arg("saddle_turns") = py::dict(),
             "A copy after the what-ifs (mm, or strings with units: mm, in, 3/32 in, thou; fret_offsets {k: mm or "
             "'level'}; action {fret: {string: gap}}; relief_change, nut_change and saddle_change: moves from where "
             "they are; truss_rod_turns (+ tighter) and saddle_turns {string: turns, + up}, where the file's "
             "[adjusters] say what a turn does; tune {string: note or Hz}; string_set: a named set's strings at the same pitches).")
        .def(py::pickle([](const Instrument& i) { return py::make_tuple(i.source_text, i.name); },
                        [](const py::tuple& t) {
                            return parse_instrument(t[0].cast<std::string>(), t[1].cast<std::string>(), DataSource::builtin());
                        }))
        .def("__repr__", [](const Instrument& i) {
            return "<fretbuzz.Instrument " + i.name + ": " + std::to_string(i.strings.size()) + " strings, " +
                   std::to_string(i.neck.fret_count) + " frets>";
        });
    m.def("load_instrument", &load_instrument, py::arg("name_or_path"),
          "A built-in instrument (see instruments()) or an instrument file (.toml).");
    m.def("instrument_from_text", [](const std::string& text, const std::string& name, const std::string& base_dir) {
              return parse_instrument(text, name, DataSource::directory(base_dir));
          },
          py::arg("text"), py::arg("name") = "instrument.toml", py::arg("base_dir") = ".",
          "An instrument from the text of an instrument file (data files relative to base_dir).");
    m.def("instruments", [] {
        py::dict d;
        for (const BuiltinInstrumentInfo& info : builtin_instruments()) d[py::str(info.name)] = info.description;
        return d;
    }, "The built-in instruments: {name: description}.");
    m.def("_setup_map", &run_map, py::arg("instrument"), py::arg("strengths"), py::arg("strings"), py::arg("frets"),
          py::arg("finger"), py::arg("jobs"), py::arg("audio_dir"), py::arg("progress"), py::arg("stop"),
          py::arg("attack_scale") = 1.0);
    m.def("_setup_check", [](const Instrument& instrument, const std::string& strengths, const py::object& strings,
                             const py::object& frets, bool finger, double attack_scale) {
              const MapRequest r = with_python_names(
                  [&] { return map_request(instrument, strengths, strings, frets, finger, 0, attack_scale); });
              return map_notes(instrument, r).size() * r.attacks.size();
          },
          py::arg("instrument"), py::arg("strengths"), py::arg("strings"), py::arg("frets"), py::arg("finger"),
          py::arg("attack_scale") = 1.0,
          "The number of notes a map would play; InputError, before anything runs, for what _setup_map would refuse.");
    m.def("_setup_calibrate", &calibrate, py::arg("instrument"), py::arg("report"), py::arg("source"), py::arg("finger"),
          py::arg("jobs"), py::arg("progress"));
    m.def("_setup_note", &record, py::arg("instrument"), py::arg("string"), py::arg("fret"), py::arg("strength"),
          py::arg("member"), py::arg("finger"), py::arg("wav") = "", py::arg("attack_scale") = 1.0);
    m.def("_setup_compare", [](const py::iterable& now, const py::iterable& before) {
        py::list rows;
        for (const NoteChange& c : compare_maps(verdicts_from(now), verdicts_from(before))) {
            py::dict d = verdict_dict(c.now);
            d["change"] = c.change;
            d["reason"] = c.reason;
            d["buzz_fraction_before"] = c.change == "new" ? py::object(py::none()) : py::object(py::float_(c.before.buzz_fraction));
            d["buzz_dB_before"] = number(c.before.buzz_db);
            d["buzz_fret_before"] = fret_value(c.before.buzz_fret);
            rows.append(d);
        }
        return rows;
    });
    m.def("_setup_advice", &advice, py::arg("instrument"), py::arg("map"), py::arg("strength"), py::arg("strings"),
          py::arg("frets"), py::arg("tolerate"), py::arg("finger"), py::arg("jobs"), py::arg("attack_scale") = 1.0,
          py::arg("progress") = py::none());
    m.def("_setup_dress", &dress, py::arg("instrument"), py::arg("map"), py::arg("strength"), py::arg("strings"),
          py::arg("frets"), py::arg("tolerate"), py::arg("depth"), py::arg("crown"), py::arg("fall_away"),
          py::arg("finger"), py::arg("jobs"), py::arg("attack_scale") = 1.0, py::arg("progress") = py::none());
    m.def("_setup_dress_check",
          [](const Instrument& instrument, const std::string& strength, const py::object& strings, const py::object& frets,
             const std::string& tolerate, const py::object& depth, const py::object& crown, const py::object& fall_away,
             bool finger, double attack_scale) {
              dress_request(instrument, strength, strings, frets, tolerate, depth, crown, fall_away, finger, 0, attack_scale);
          },
          py::arg("instrument"), py::arg("strength"), py::arg("strings"), py::arg("frets"), py::arg("tolerate"),
          py::arg("depth"), py::arg("crown"), py::arg("fall_away"), py::arg("finger"), py::arg("attack_scale") = 1.0,
          "InputError, before anything is played, for what _setup_dress would refuse of its arguments.");
    m.def("_setup_tolerance", [](const Instrument& instrument, const std::string& text) {
              return tolerance_for(instrument, text, "tolerate").text();
          },
          py::arg("instrument"), py::arg("text"), "What the advice tolerates, in words; InputError for a bad value.");
    m.def("_setup_attack_scale", [](double scale) {
              return checked_attack_scale("attack_scale", scale, " (a calibration's attack_scale; 1: the attacks as they are)");
          },
          py::arg("scale"), "The scale if a calibration can have found it, else InputError naming its range.");
    m.def("_setup_player_scale", [](const std::string& path) { return read_player_touch(path, "calibration").attack_scale; },
          py::arg("path"), "The attack_scale of a calibration.json, read and checked as --player reads it.");
    m.def("_compressed_audio", &compressed_audio, py::arg("wav"), py::arg("out"),
          "Writes the sound of a WAV file as Ogg Vorbis (a report's embedded sounds: a tenth of the size).");
}

}  // namespace fretbuzz::python
