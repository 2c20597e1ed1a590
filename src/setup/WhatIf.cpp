#include "fretbuzz/setup/WhatIf.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/InstrumentFile.hpp"
#include "fretbuzz/input/InstrumentUnits.hpp"
#include "fretbuzz/model/SteelWire.hpp"
#include "fretbuzz/model/TautString.hpp"
#include "fretbuzz/setup/StringNeck.hpp"

namespace fretbuzz {

namespace {

std::string mm(double metres) {
    std::ostringstream out;
    out.precision(4);
    out << metres * 1e3;
    return out.str();
}

void require_mm(const std::string& option, double value, double low, double high) {
    if (!(value >= low && value <= high))
        throw InputError(option + " = " + mm(value) + " mm is out of range: must be in [" + mm(low) + ", " + mm(high) +
                         "] mm");
}

// Every string still clears every fret; a message naming the option that moved it.
void check_strings(const Instrument& instrument, const std::string& option) {
    for (std::size_t s = 0; s < instrument.strings.size(); ++s) {
        try {
            StringNeck neck(instrument, s);
        } catch (const InputError& e) {
            throw InputError(option + ": " + e.what());
        }
    }
}

// New strings (a named set's, at the same pitches) or a retuning: each string's tension
// follows from its mass and pitch (T = mu (2 L f)^2), and the neck bows with the pull.
void change_strings(Instrument& out, const SetupChange& change) {
    if (change.string_set) {
        const std::string option = "--set " + *change.string_set;
        const StringSet& set = builtin_string_set(*change.string_set, "--set");
        if (set.strings.size() != out.strings.size())
            throw InputError(option + ": the set has " + std::to_string(set.strings.size()) + " strings; " + out.name +
                             " has " + std::to_string(out.strings.size()));
        for (std::size_t k = 0; k < out.strings.size(); ++k) {
            InstrumentString& s = out.strings[k];
            const StringSetEntry& e = set.strings[k];
            s.gauge_m = e.gauge_m;
            s.linear_density = e.linear_density;
            s.bending_stiffness = SteelWire{e.core_m}.bending_stiffness();
            s.tension_n = TautString::tuned_with_mass(s.scale_length_m, s.linear_density, s.frequency_hz).tension_n;
            s.tension_source = "string set " + set.name + " (" + set.source + ")";
        }
        check_strings(out, option);
    }
    for (const auto& [name, pitch] : change.pitch_hz) {
        const std::string option = "--tune " + name;
        InstrumentString& s = out.strings[out.string_index(name)];
        if (!(pitch >= 20.0 && pitch <= 2000.0))
            throw InputError(out_of_range_message(option + " (Hz)", pitch, "must be in [20, 2000] Hz"));
        const double tension = TautString::tuned_with_mass(s.scale_length_m, s.linear_density, pitch).tension_n;
        if (!(tension >= 1.0 && tension <= 1500.0))
            throw InputError(option + ": the string would pull " + std::to_string(tension) +
                             " N at that pitch, out of range: must be in [1, 1500] N");
        s.frequency_hz = pitch;
        s.tension_n = tension;
        check_strings(out, option);
    }
}

// "E=2.2mm" as NAME and VALUE; InputError naming the option and the form it takes.
std::pair<std::string, std::string> name_value(const std::string& text, const std::string& option,
                                               const std::string& form) {
    const std::size_t eq = text.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == text.size())
        throw InputError(option + " " + text + ": give " + form);
    return {text.substr(0, eq), text.substr(eq + 1)};
}

// The string called `name`; InputError naming the option and the strings there are if none is.
void check_string(const Instrument& instrument, const std::string& name, const std::string& option) {
    try {
        instrument.string_index(name);
    } catch (const InputError& e) {
        throw InputError(option + ": " + e.what());
    }
}

}  // namespace

std::vector<std::string> WhatIfWords::words() const {
    std::vector<std::string> out;
    const auto add = [&](const std::string& option, const std::vector<std::string>& values) {
        for (const std::string& v : values) out.push_back(option + " " + v);
    };
    if (!string_set.empty()) out.push_back("--set " + string_set);
    add("--tune", tune);
    if (!relief.empty()) out.push_back("--relief " + relief);
    if (!relief_change.empty()) out.push_back("--relief-change " + relief_change);
    if (!truss_rod_turns.empty()) out.push_back("--truss-rod-turns " + truss_rod_turns);
    add("--action12", action12);
    add("--action", action);
    add("--nut", nut);
    add("--nut-change", nut_change);
    add("--saddle", saddle);
    add("--saddle-change", saddle_change);
    add("--saddle-turns", saddle_turns);
    add("--fret-offset", fret_offsets);
    return out;
}

WhatIfReading read_what_ifs(const WhatIfWords& w, const Instrument& instrument) {
    WhatIfReading r;
    SetupChange& c = r.change;
    const std::string bare = written_length_unit(instrument.units);
    const std::string units = " (a length with its unit: mm, in, 3/32in, 5/64\", 12thou; a bare number is in " + bare +
                              ", the instrument file's units)";
    const auto length = [&](const std::string& text, const std::string& option, const std::string& what) {
        const LengthAsRead l = read_length(text, bare, option);
        r.as_read.push_back(what + ": " + l.as_read);
        return l.metres;
    };
    if (!w.string_set.empty()) c.string_set = w.string_set;
    for (const std::string& item : w.tune) {
        const auto [name, value] = name_value(item, "--tune", "STRING=PITCH, e.g. --tune E=D2 or E=41.2Hz");
        check_string(instrument, name, "--tune " + item);
        c.pitch_hz.emplace_back(name, parse_quantity_or(value, Quantity::frequency, "Hz", "--tune " + name));
    }
    if (!w.relief.empty()) c.relief_m = length(w.relief, "--relief", "relief");
    if (!w.relief_change.empty()) c.relief_change_m = length(w.relief_change, "--relief-change", "relief change");
    const auto per_string = [&](const std::vector<std::string>& given, const std::string& option, const std::string& what,
                                const std::string& example, auto&& add) {
        for (const std::string& item : given) {
            const auto [name, value] = name_value(item, option, "STRING=LENGTH, e.g. " + option + " " + example + units);
            check_string(instrument, name, option + " " + item);
            add(name, length(value, option + " " + name, what + ", " + name));
        }
    };
    per_string(w.action12, "--action12", "action at fret 12", "E=2.2mm",
               [&](const std::string& name, double m) { c.action_m.push_back({name, 12, m}); });
    for (const std::string& item : w.action) {
        const std::string form = "FRET:STRING=LENGTH, e.g. --action 17:E=3/32in" + units;
        const auto [where, value] = name_value(item, "--action", form);
        const std::size_t colon = where.find(':');
        if (colon == std::string::npos || colon == 0 || colon + 1 == where.size())
            throw InputError("--action " + item + ": give " + form);
        const std::string name = where.substr(colon + 1);
        const std::size_t fret = whole_number(where.substr(0, colon), "--action", 2, instrument.neck.fret_count,
                                              "the fret (2 to the last fret, " +
                                                  std::to_string(instrument.neck.fret_count) + "; fret 1 is --nut)");
        check_string(instrument, name, "--action " + item);
        c.action_m.push_back(
            {name, fret, length(value, "--action " + where, "action at fret " + std::to_string(fret) + ", " + name)});
    }
    const auto into = [](auto& list) { return [&list](const std::string& name, double m) { list.emplace_back(name, m); }; };
    per_string(w.nut, "--nut", "nut (gap over fret 1)", "E=0.5mm", into(c.nut_m));
    per_string(w.nut_change, "--nut-change", "nut change", "E=-0.1mm", into(c.nut_change_m));
    per_string(w.saddle, "--saddle", "saddle", "E=12mm", into(c.saddle_m));
    per_string(w.saddle_change, "--saddle-change", "saddle change", "E=-0.25mm", into(c.saddle_change_m));
    if (!w.truss_rod_turns.empty()) {
        c.truss_rod_turns = screw_turns(w.truss_rod_turns, "--truss-rod-turns", kMostTrussRodTurns);
        r.as_read.push_back("truss rod: " + number_text(*c.truss_rod_turns) + " turn (+ tighter)");
    }
    for (const std::string& item : w.saddle_turns) {
        const auto [name, value] = name_value(item, "--saddle-turns", "STRING=TURNS, e.g. --saddle-turns E=-1/2 (+ up)");
        check_string(instrument, name, "--saddle-turns " + item);
        c.saddle_turns.emplace_back(name, screw_turns(value, "--saddle-turns " + name, kMostSaddleTurns));
        r.as_read.push_back("saddle screws, " + name + ": " + number_text(c.saddle_turns.back().second) + " turn (+ up)");
    }
    for (const std::string& item : w.fret_offsets) {
        const auto [fret, value] = name_value(item, "--fret-offset", "FRET=LENGTH or FRET=level, e.g. --fret-offset 15=0.08mm" + units);
        FretChange f;
        f.fret = whole_number(fret, "--fret-offset", 1, instrument.neck.fret_count,
                              "the fret (1 to the last fret, " + std::to_string(instrument.neck.fret_count) + ")");
        if (value != "level") f.by_m = length(value, "--fret-offset " + fret, "fret " + fret + " offset");
        c.frets.push_back(f);
    }
    return r;
}

std::optional<PullChange> pull_change(const Instrument& before, const Instrument& after) {
    const double was = strings_pull(before), now = strings_pull(after);
    if (was == now || after.strings.empty() || after.neck.fret_count < 3) return std::nullopt;
    PullChange c;
    c.before_n = was;
    c.after_n = now;
    c.fret = relief_fret(after);
    c.relief_before_m = StringNeck(before, 0).relief_gap(c.fret);
    c.relief_after_m = StringNeck(after, 0).relief_gap(c.fret);
    const StringNeck first(after, 0);
    c.bow_m = pull_bow(after, first.fret_x(first.fret_count())) - pull_bow(before, first.fret_x(first.fret_count()));
    return c;
}

double proud_height(const Instrument& instrument, std::size_t fret) {
    const std::size_t last = instrument.neck.fret_count;
    if (fret < 1 || fret > last || last < 3) return 0.0;
    double height = -std::numeric_limits<double>::infinity();
    for (std::size_t s = 0; s < instrument.strings.size(); ++s) {
        const StringNeck n(instrument, s);
        const std::size_t a = fret == last ? fret - 2 : fret - 1;
        const std::size_t b = fret == last ? fret - 1 : fret + 1;
        const double line =
            n.fret_top(a) + (n.fret_top(b) - n.fret_top(a)) * (n.fret_x(fret) - n.fret_x(a)) / (n.fret_x(b) - n.fret_x(a));
        height = std::max(height, n.fret_top(fret) - line);
    }
    return height;
}

std::size_t relief_fret(const Instrument& instrument) {
    if (instrument.neck.relief.form == ReliefMeasure::Form::gap) return instrument.neck.relief.at_fret;
    return std::min<std::size_t>(8, instrument.neck.fret_count - 1);
}

Instrument with_pinned_string_ends(const Instrument& instrument) {
    Instrument pinned = instrument;
    for (std::size_t s = 0; s < instrument.strings.size(); ++s) {
        const StringNeck neck(instrument, s);
        pinned.strings[s].nut = {StringEnd::Form::height, neck.nut_height(), 0};
        pinned.strings[s].bridge = {StringEnd::Form::height, neck.saddle_height(), 0};
        pinned.strings[s].body_height_m = neck.body_height();
    }
    return pinned;
}

Instrument apply_change(const Instrument& instrument, const SetupChange& change) {
    if (change.empty()) return instrument;
    Instrument out = with_pinned_string_ends(instrument);
    NeckDescription& neck = out.neck;
    change_strings(out, change);
    const int rod_moves = change.relief_m.has_value() + change.relief_change_m.has_value() + change.truss_rod_turns.has_value();
    if (rod_moves > 0) {
        if (rod_moves > 1)
            throw InputError("--relief, --relief-change and --truss-rod-turns each set the truss rod: give one of them");
        const std::string option = change.relief_m ? "--relief" : change.relief_change_m ? "--relief-change" : "--truss-rod-turns";
        const std::size_t m = relief_fret(out);
        if (neck.fret_count < 3) throw InputError(option + ": the neck needs at least 3 frets to measure relief");
        // The gap is linear in the truss rod's bow: one look at the current gap does it.
        const StringNeck now(out, 0);
        const double gap = now.relief_gap(m);
        std::optional<double> by = change.relief_change_m;
        if (by) require_mm("--relief-change", *by, -1e-3, 1e-3);
        if (change.truss_rod_turns) {
            const double per_turn = out.adjusters.truss_rod_turn_m;
            if (!(per_turn > 0.0))
                throw InputError("--truss-rod-turns needs adjusters.truss_rod_turn in the instrument file: the relief "
                                 "one full turn tighter takes off at fret " + std::to_string(m) + ", measured on this neck");
            if (!(std::abs(*change.truss_rod_turns) <= kMostTrussRodTurns))
                throw InputError(out_of_range_message(option, *change.truss_rod_turns,
                                                      "must be in [-" + number_text(kMostTrussRodTurns) + ", " +
                                                          number_text(kMostTrussRodTurns) + "] turns"));
            by = -*change.truss_rod_turns * per_turn;  // tighter (clockwise): the rod pulls the bow out
        }
        const double target = change.relief_m ? *change.relief_m : gap + *by;
        require_mm(change.relief_m ? "--relief (the gap at fret " + std::to_string(m) + ")"
                                   : option + " (the gap at fret " + std::to_string(m) + " after it, " + mm(gap) + " mm now)",
                   target, -2e-3, 2e-3);
        neck.truss_rod_bow_m += (target - gap) / relief_gap_per_bow(now, m);
        check_strings(out, option);
    }
    for (const FretChange& f : change.frets) {
        const std::string option = "--fret-offset " + std::to_string(f.fret);
        if (f.fret < 1 || f.fret > neck.fret_count)
            throw InputError(option + ": fret " + std::to_string(f.fret) + " does not exist (frets 1 to " +
                             std::to_string(neck.fret_count) + ")");
        double by = 0.0;
        if (f.by_m) {
            by = *f.by_m;
            require_mm(option, by, -1e-3, 1e-3);
        } else {
            // Dressed down to the line through its neighbours' tops under every string.
            by = -proud_height(out, f.fret);
            if (!(by < 0.0))
                throw InputError(option + "=level: fret " + std::to_string(f.fret) +
                                 " is not proud of its neighbours (it lies " + mm(by) +
                                 " mm below their line): levelling would not touch it");
        }
        const double now = neck.fret_offset_m.contains(f.fret) ? neck.fret_offset_m[f.fret] : 0.0;
        const double offset = now + by;
        if (!(offset >= -neck.fret_height_m && offset <= 1e-3))
            throw InputError(option + ": its top would end " + mm(offset) + " mm off the fret line; it must stay in [-" +
                             mm(neck.fret_height_m) + " (down to the board), 1] mm");
        neck.fret_offset_m[f.fret] = offset;
        check_strings(out, option);
    }
    // Each string end is set by one option at most; the option that set it, by string.
    std::map<std::size_t, std::string> nut_by, saddle_by;
    const auto set_end = [&](std::map<std::size_t, std::string>& by, const std::string& option, const std::string& name,
                             auto&& set) {
        const std::size_t s = out.string_index(name);
        if (const auto was = by.find(s); was != by.end())
            throw InputError(option + ": " + was->second + " already sets string " + name + "'s " +
                             (&by == &nut_by ? "nut" : "saddle") + ": give one of them");
        by.emplace(s, option);
        set(out.strings[s], StringNeck(out, s));
        check_strings(out, option);
    };
    for (const ActionChange& a : change.action_m) {
        const std::string option =
            a.fret == 12 ? "--action12 " + a.string : "--action " + std::to_string(a.fret) + ":" + a.string;
        if (a.fret < 2 || a.fret > neck.fret_count)
            throw InputError(option + ": the action is set at a fret from 2 to the last, " +
                             std::to_string(neck.fret_count) + " (the gap over fret 1 is --nut)");
        require_mm(option, a.gap_m, 1e-5, 10e-3);
        set_end(saddle_by, option, a.string, [&a](InstrumentString& s, const StringNeck&) {
            s.bridge = {StringEnd::Form::gap_over_fret, a.gap_m, a.fret};
        });
    }
    // A relative move: a nut's or a saddle's height above the fret plane changed by an amount.
    const auto move_end = [&](bool nut, const std::vector<std::pair<std::string, double>>& moves, double most,
                              double highest, const std::string& option_word) {
        const std::string end = nut ? "nut" : "saddle";
        for (const auto& [name, by] : moves) {
            const std::string option = option_word + name;
            require_mm(option, by, -most, most);
            set_end(nut ? nut_by : saddle_by, option, name, [&, by = by](InstrumentString& s, const StringNeck& now) {
                const double height = nut ? now.nut_height() : now.saddle_height();
                require_mm(option + " (the " + end + "'s height after it, " + mm(height) + " mm now)", height + by, 1e-5,
                           highest);
                (nut ? s.nut : s.bridge) = {StringEnd::Form::height, height + by, 0};
            });
        }
    };
    for (const auto& [name, value] : change.nut_m) {
        require_mm("--nut " + name, value, 1e-5, 5e-3);
        set_end(nut_by, "--nut " + name, name, [gap = value](InstrumentString& s, const StringNeck&) {
            s.nut = {StringEnd::Form::gap_over_fret, gap, 1};
        });
    }
    move_end(true, change.nut_change_m, 2e-3, 10e-3, "--nut-change ");
    for (const auto& [name, value] : change.saddle_m) {
        require_mm("--saddle " + name, value, 1e-5, 30e-3);
        set_end(saddle_by, "--saddle " + name, name, [height = value](InstrumentString& s, const StringNeck&) {
            s.bridge = {StringEnd::Form::height, height, 0};
        });
    }
    move_end(false, change.saddle_change_m, 5e-3, 30e-3, "--saddle-change ");
    // Saddle screws: the thread's pitch per turn, a relative move as --saddle-change's.
    if (!change.saddle_turns.empty()) {
        const double pitch = out.adjusters.saddle_screw_pitch_m;
        std::vector<std::pair<std::string, double>> moves;
        for (const auto& [name, turns] : change.saddle_turns) {
            const std::string option = "--saddle-turns " + name;
            if (!(pitch > 0.0))
                throw InputError(option + " needs adjusters.saddle_screw_pitch in the instrument file: the thread's "
                                 "pitch of the saddles' height screws (a 4-40 screw: 1/40 in)");
            if (!(std::abs(turns) <= kMostSaddleTurns))
                throw InputError(out_of_range_message(option, turns, "must be in [-" + number_text(kMostSaddleTurns) +
                                                                         ", " + number_text(kMostSaddleTurns) + "] turns"));
            moves.emplace_back(name, turns * pitch);
        }
        move_end(false, moves, kMostSaddleTurns * pitch, 30e-3, "--saddle-turns ");
    }
    return out;
}

}  // namespace fretbuzz
