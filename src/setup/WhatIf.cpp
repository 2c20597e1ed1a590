#include "fretbuzz/setup/WhatIf.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/InstrumentFile.hpp"
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

}  // namespace

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
    if (change.relief_m) {
        const std::size_t m = relief_fret(out);
        require_mm("--relief (the gap at fret " + std::to_string(m) + ")", *change.relief_m, -2e-3, 2e-3);
        if (neck.fret_count < 3) throw InputError("--relief: the neck needs at least 3 frets to measure relief");
        // The gap is linear in the truss rod's bow: one look at the current gap does it.
        const StringNeck now(out, 0);
        neck.truss_rod_bow_m += (*change.relief_m - now.relief_gap(m)) / relief_gap_per_bow(now, m);
        check_strings(out, "--relief");
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
    const auto set_end = [&](const std::string& option, const std::string& name, auto&& set) {
        const std::size_t s = out.string_index(name);
        set(out.strings[s]);
        check_strings(out, option + " " + name);
    };
    for (const auto& [name, value] : change.action12_m) {
        if (neck.fret_count < 12) throw InputError("--action12: the neck has only " + std::to_string(neck.fret_count) + " frets");
        require_mm("--action12 " + name, value, 1e-5, 10e-3);
        set_end("--action12", name, [gap = value](InstrumentString& s) { s.bridge = {StringEnd::Form::gap_over_fret, gap, 12}; });
    }
    for (const auto& [name, value] : change.nut_m) {
        require_mm("--nut " + name, value, 1e-5, 5e-3);
        set_end("--nut", name, [gap = value](InstrumentString& s) { s.nut = {StringEnd::Form::gap_over_fret, gap, 1}; });
    }
    for (const auto& [name, value] : change.saddle_m) {
        require_mm("--saddle " + name, value, 1e-5, 30e-3);
        set_end("--saddle", name, [height = value](InstrumentString& s) { s.bridge = {StringEnd::Form::height, height, 0}; });
    }
    return out;
}

}  // namespace fretbuzz
