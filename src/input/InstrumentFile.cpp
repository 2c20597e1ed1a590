// Instrument files (docs/instrument-format.md): [neck] (with [neck.relief]), [strings],
// [[string]], [attack], [damping], [contact], [simulation]. Dimensional values are strings
// with their unit ("2.4 mm", "5/64 in"); each is checked against its range here, and the
// message names the key, the value as written and the range in the unit a luthier uses.
#include "fretbuzz/input/InstrumentFile.hpp"

#include <algorithm>
#include <cmath>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <numbers>
#include <set>
#include <sstream>

#include "TomlSection.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/geometry/FretPositions.hpp"
#include "fretbuzz/input/BuiltinFiles.hpp"
#include "fretbuzz/input/CsvTable.hpp"
#include "fretbuzz/input/InstrumentUnits.hpp"
#include "fretbuzz/input/TextFile.hpp"
#include "fretbuzz/model/SteelWire.hpp"
#include "fretbuzz/model/TautString.hpp"

namespace fretbuzz {

namespace {

constexpr std::string_view kInstrumentDir = "instruments/";
constexpr std::string_view kSuffix = ".toml";
constexpr std::string_view kSetsFile = "strings/sets.toml";
constexpr std::size_t kMaxStrings = 12;
constexpr std::size_t kMaxFrets = 24;  // a stopped string reaches 3 L / 4 at most (stopped_string)

// An interval in a display unit, for checks and their messages: "(0, 5] mm".
struct Range {
    double low, high;  // in the display unit
    bool low_open, high_open;
    std::string_view unit;  // "mm", "m", "N", "Hz", ... ("" for pure numbers)
    double factor;          // display unit -> SI

    std::string text() const {
        std::string t = std::string(low_open ? "(" : "[") + number_text(low) + ", " + number_text(high) +
                        (high_open ? ")" : "]");
        return unit.empty() ? t : t + " " + std::string(unit);
    }
    bool contains(double si) const {
        const double v = si / factor;
        return (low_open ? v > low : v >= low) && (high_open ? v < high : v <= high);
    }
};

constexpr Range mm(double low, double high, bool low_open = true, bool high_open = false) {
    return {low, high, low_open, high_open, "mm", 1e-3};
}

// A string's gap over a fret and its heights at the ends: the what-ifs' ranges
// (src/setup/WhatIf.cpp), so that a value a file takes is one a what-if takes.
constexpr Range string_end_mm(double high) { return mm(0.01, high, false, false); }

class Reader {
public:
    explicit Reader(const DataSource& data) : data_(data) {}

    // A dimensional value: a string with its unit, checked against `range`.
    double quantity(TomlSection& s, std::string_view key, Quantity kind, const Range& range) {
        const std::string path = s.key_path(key);
        const toml::node* n = s.node(key);
        if (n == nullptr) throw InputError(path + " is missing (required; " + range.text() + ")");
        return checked(*n, path, kind, range);
    }
    std::optional<double> optional_quantity(TomlSection& s, std::string_view key, Quantity kind, const Range& range) {
        if (!s.has(key)) return std::nullopt;
        return quantity(s, key, kind, range);
    }
    // A node holding a quantity (an array item, a table entry).
    static double checked(const toml::node& n, const std::string& path, Quantity kind, const Range& range) {
        std::string text;
        if (const auto* str = n.as_string()) {
            text = str->get();
        } else if (n.is_number()) {
            // As written: an integer past 2^53 has no exact double (toml++ then gives none).
            const auto* integer = n.as_integer();
            const std::string shown = integer ? std::to_string(integer->get()) : number_text(n.value<double>().value_or(0.0));
            throw InputError(path + " = " + shown + ": say its unit, e.g. \"" + shown + " " +
                             std::string(range.unit.empty() ? "" : range.unit) + "\" (units: " + unit_names(kind) + ")");
        } else {
            throw InputError(path + " must be a string with a unit (units: " + unit_names(kind) + ")");
        }
        const double v = parse_quantity(text, kind, path);
        if (!range.contains(v))
            throw InputError(path + " = \"" + text + "\" is out of range: must be in " + range.text());
        return v;
    }
    static double number_in(TomlSection& s, std::string_view key, const Range& range) {
        const double v = s.number(key);
        if (!range.contains(v))
            throw InputError(out_of_range_message(s.key_path(key), v, "must be in " + range.text()));
        return v;
    }

    CsvTable table(TomlSection& s, std::string_view key, std::size_t min_columns) const {
        const std::string file = s.text(key);
        const std::string path = s.key_path(key);
        const std::string text = data_.read(file, path);
        try {
            return parse_csv(text, file, min_columns);
        } catch (const InputError& e) {
            throw InputError(path + " = \"" + file + "\": " + e.what());
        }
    }

private:
    const DataSource& data_;
};

// Multiscale: the first string's and the last string's scale lengths.
std::vector<double> read_scales(Reader& r, TomlSection& neck) {
    const Range scale{0.2, 1.5, false, false, "m", 1.0};
    const toml::node* n = neck.node("scale");
    if (n == nullptr) throw InputError(neck.key_path("scale") + " is missing (required; in " + scale.text() + ")");
    if (const auto* array = n->as_array()) {
        if (array->size() != 2)
            throw InputError(neck.key_path("scale") +
                             " must be one length or two (multiscale: the first string's, the last string's)");
        return {r.checked(*array->get(0), neck.key_path("scale[0]"), Quantity::length, scale),
                r.checked(*array->get(1), neck.key_path("scale[1]"), Quantity::length, scale)};
    }
    return {r.checked(*n, neck.key_path("scale"), Quantity::length, scale)};
}

ReliefMeasure read_relief(Reader& r, TomlSection& s, std::size_t frets, double shortest_last_fret) {
    ReliefMeasure relief;
    const bool gap = s.has("gap"), curve = s.has("curve");
    if (gap && curve)
        throw InputError(s.key_path("gap") + " and " + s.key_path("curve") + " are both given: give one");
    // fret says where the gap is measured: without the gap it says nothing (not an unknown key).
    if (!gap && s.has("fret"))
        throw InputError(s.key_path("fret") + " is the fret the relief gap is measured at: give " + s.key_path("gap") +
                         " with it (e.g. gap = \"0.3 mm\")" + (curve ? ", or the curve alone" : ""));
    if (gap) {
        relief.form = ReliefMeasure::Form::gap;
        relief.gap_m = r.quantity(s, "gap", Quantity::length, mm(-2.0, 2.0, false, false));
        if (frets < 3)
            throw InputError(s.key_path("gap") + ": measuring relief needs at least 3 frets (neck.frets = " +
                             std::to_string(frets) + ")");
        relief.at_fret = s.optional_count("fret", 2, frets - 1).value_or(std::min<std::size_t>(8, frets - 1));
    } else if (curve) {
        relief.form = ReliefMeasure::Form::curve;
        const toml::node* n = s.node("curve");
        const auto* array = n->as_array();
        const std::string expected =
            " must be an array of [x, depth] pairs with units, e.g. [[\"178 mm\", \"0.41 mm\"], [\"319 mm\", \"0.6 mm\"]]";
        if (array == nullptr || array->empty()) throw InputError(s.key_path("curve") + expected);
        for (std::size_t k = 0; k < array->size(); ++k) {
            const std::string item = s.key_path("curve") + "[" + std::to_string(k) + "]";
            const auto* pair = array->get(k)->as_array();
            if (pair == nullptr || pair->size() != 2) throw InputError(item + expected);
            const Range inside{0.0, shortest_last_fret * 1e3, true, true, "mm", 1e-3};
            const double x = Reader::checked(*pair->get(0), item + "[0] (x from the nut)", Quantity::length, inside);
            if (!relief.x_m.empty() && !(x > relief.x_m.back()))
                throw InputError(item + "[0] (x from the nut): the points must go from the nut toward the body");
            relief.x_m.push_back(x);
            relief.depth_m.push_back(
                Reader::checked(*pair->get(1), item + "[1] (depth)", Quantity::length, mm(-5.0, 5.0, false, false)));
        }
    }
    s.finish();
    return relief;
}

// Reads a table; when that fails while one of its keys is a likely misspelling of a key it
// looked for in vain ("acton12" for "action12"), the misspelling is what is reported.
template <class Read>
auto read_with_key_check(TomlSection& s, Read read) -> decltype(read()) {
    try {
        return read();
    } catch (const InputError&) {
        s.refuse_misspelt_keys();
        throw;
    }
}

// One radius (a cylindrical board) or two: at the nut and at the last fret (a compound,
// conical board whose radius grows linearly along the neck).
void read_radius(TomlSection& s, NeckDescription& neck) {
    const Range radius = mm(50.0, 5000.0, false, false);
    const toml::node* n = s.node("radius");
    if (n == nullptr) return;
    if (const auto* array = n->as_array()) {
        if (array->size() != 2)
            throw InputError(s.key_path("radius") + " must be one radius or two (a compound board: at the nut and at "
                                                     "the last fret), e.g. [\"10 in\", \"16 in\"]");
        neck.radius_m = Reader::checked(*array->get(0), s.key_path("radius[0]"), Quantity::length, radius);
        neck.radius_last_fret_m = Reader::checked(*array->get(1), s.key_path("radius[1]"), Quantity::length, radius);
        return;
    }
    neck.radius_m = Reader::checked(*n, s.key_path("radius"), Quantity::length, radius);
}

// A capo, and the neck's stiffness under the strings' pull (geometry/NeckBeam.hpp).
void read_capo_and_beam(Reader& r, TomlSection& s, NeckDescription& neck) {
    if (s.has("capo")) {
        if (neck.fret_count < 2)
            throw InputError(s.key_path("capo") + ": a capo needs a neck of at least 2 frets (a fret to play above it)");
        neck.capo = s.count("capo", 1, neck.fret_count - 1);
    }
    neck.beam.bending_stiffness_n_m2 =
        r.optional_quantity(s, "stiffness", Quantity::bending_stiffness, {20.0, 20000.0, false, false, "N m^2", 1.0})
            .value_or(neck.beam.bending_stiffness_n_m2);
    neck.beam.pull_height_m =
        r.optional_quantity(s, "pull_height", Quantity::length, mm(0.0, 50.0)).value_or(neck.beam.pull_height_m);
}

void read_neck(Reader& r, TomlSection& s, std::size_t string_count, Instrument& inst, std::vector<double>& scales) {
    NeckDescription& neck = inst.neck;
    scales = read_scales(r, s);
    neck.fret_count = s.count("frets", 1, kMaxFrets);
    if (scales.size() == 2) {
        neck.perpendicular_fret = s.optional_count("perpendicular_fret", 0, neck.fret_count).value_or(0);
        if (string_count < 2)
            throw InputError(s.key_path("scale") + ": two scale lengths (multiscale) need at least two strings");
    }
    const double shortest = *std::min_element(scales.begin(), scales.end());
    const double last_fret = fret_position(shortest, neck.fret_count);
    neck.fret_height_m = r.quantity(s, "fret_height", Quantity::length, mm(0.0, 5.0));
    if (const toml::node* offsets = s.node("fret_offsets")) {
        const auto* table = offsets->as_table();
        if (table == nullptr)
            throw InputError(s.key_path("fret_offsets") + " must be a table of fret = \"offset\", e.g. { 9 = \"0.05 mm\" }");
        for (const auto& [name, value] : *table) {
            const std::string path = s.key_path("fret_offsets." + std::string(name.str()));
            std::size_t fret = 0;
            const auto [end, error] = std::from_chars(name.str().data(), name.str().data() + name.str().size(), fret);
            if (error != std::errc() || end != name.str().data() + name.str().size() || fret < 1 ||
                fret > neck.fret_count)
                throw InputError(path + ": fret \"" + std::string(name.str()) + "\" does not exist (frets 1 to " +
                                 std::to_string(neck.fret_count) + ")");
            neck.fret_offset_m[fret] =
                Reader::checked(value, path, Quantity::length, mm(-neck.fret_height_m * 1e3, 1.0, false, false));
        }
    }
    if (auto relief = s.optional_section("relief"))
        neck.relief = read_with_key_check(*relief, [&] { return read_relief(r, *relief, neck.fret_count, last_fret); });
    if (neck.relief.form == ReliefMeasure::Form::gap && neck.fret_count < 3)
        throw InputError(s.key_path("relief.gap") + ": measuring relief needs at least 3 frets");
    neck.truss_rod_bow_m = 0.0;
    read_radius(s, neck);
    read_capo_and_beam(r, s, neck);
    const auto nut_width = r.optional_quantity(s, "nut_width", Quantity::length, mm(0.0, 120.0, false, false));
    const auto bridge = r.optional_quantity(s, "bridge_spacing", Quantity::length, mm(0.0, 200.0, false, false));
    if (neck.radius_m && string_count > 1 && (!nut_width || !bridge))
        throw InputError(s.key_path(nut_width ? "bridge_spacing" : "nut_width") +
                         " is missing (required with neck.radius: the strings' distance from the neck's centre line)");
    // Without a radius the spread is only drawn: 7 mm and 10.5 mm between strings.
    const double gaps = static_cast<double>(string_count > 1 ? string_count - 1 : 0);
    neck.nut_width_m = nut_width.value_or(7e-3 * gaps);
    neck.bridge_spacing_m = bridge.value_or(10.5e-3 * gaps);
    neck.board_end_m = r.optional_quantity(s, "board_end", Quantity::length,
                                           {last_fret * 1e3, shortest * 1e3, false, true, "mm", 1e-3})
                           .value_or(std::min(last_fret + 5e-3, 0.5 * (last_fret + shortest)));
    neck.body_depth_m = r.optional_quantity(s, "body_depth", Quantity::length, mm(0.0, 50.0));
}

// The name becomes a folder's (the studio's studio-NAME, in the current folder): one path
// component whatever the file says, plain enough to print in a page or a shell.
void check_instrument_name(const std::string& name, const std::string& key) {
    constexpr std::size_t kMaxName = 64;
    const bool plain = std::all_of(name.begin(), name.end(), [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_' ||
               c == '.' || c == ' ';
    });
    if (!plain || name.empty() || name.size() > kMaxName || name.front() == '.' || name.front() == ' ' ||
        name.find("..") != std::string::npos)
        throw InputError(key + " = \"" + name + "\": must be 1 to " + std::to_string(kMaxName) +
                         " letters (a-z, A-Z), digits, '-', '_', '.' or spaces, not starting with '.' or a space and "
                         "without \"..\" (it names the studio's folder, studio-NAME)");
}

std::vector<double> string_scales(const std::vector<double>& scales, std::size_t count) {
    std::vector<double> each(count, scales.front());
    if (scales.size() == 2 && count > 1)
        for (std::size_t k = 0; k < count; ++k)
            each[k] = scales[0] + (scales[1] - scales[0]) * static_cast<double>(k) / static_cast<double>(count - 1);
    return each;
}

std::vector<StringSet> read_string_sets();

// The built-in sets, read once.
const std::vector<StringSet>& string_sets() {
    static const std::vector<StringSet> sets = read_string_sets();
    return sets;
}


StringEnd read_nut(Reader& r, TomlSection& s, bool profile) {
    const bool gap = s.has("nut"), height = s.has("nut_height");
    if (profile && !gap && !height) return {StringEnd::Form::as_measured, 0.0, 0};
    if (gap == height)
        throw InputError(gap ? s.key_path("nut") + " and " + s.key_path("nut_height") + " are both given: give one"
                             : s.key_path("nut") + " is missing (required: the gap between the open string and the top "
                                                   "of fret 1, in [0.01, 5] mm; or nut_height)");
    if (gap) return {StringEnd::Form::gap_over_fret, r.quantity(s, "nut", Quantity::length, string_end_mm(5.0)), 1};
    return {StringEnd::Form::height, r.quantity(s, "nut_height", Quantity::length, string_end_mm(10.0)), 0};
}

StringEnd read_bridge_end(Reader& r, TomlSection& s, std::size_t frets, bool profile) {
    // "action17" is no key: the action at a fret other than 12 is action with action_fret.
    for (const std::string& key : s.keys()) {
        const std::string_view fret = std::string_view(key).substr(std::min<std::size_t>(key.size(), 6));
        if (key.starts_with("action") && key != "action12" && !fret.empty() &&
            std::all_of(fret.begin(), fret.end(), [](char c) { return c >= '0' && c <= '9'; }))
            throw InputError("unknown key " + s.key_path(key) + ": the gap over fret " + std::string(fret) +
                             " is written action = \"...\" with action_fret = " + std::string(fret) +
                             " (action12 is the shorthand for fret 12)");
    }
    const int given = int(s.has("action12")) + int(s.has("action")) + int(s.has("saddle_height"));
    if (profile && given == 0) return {StringEnd::Form::as_measured, 0.0, 0};
    if (given != 1)
        throw InputError(given == 0 ? s.key_path("action12") +
                                          " is missing (required: the gap between the open string and the top of "
                                          "fret 12, in [0.01, 10] mm; or action with action_fret, or saddle_height)"
                                    : s.key_path("action12") + ", action and saddle_height: give one of them");
    if (s.has("saddle_height"))
        return {StringEnd::Form::height, r.quantity(s, "saddle_height", Quantity::length, string_end_mm(30.0)), 0};
    if (s.has("action12")) {
        if (frets < 12)
            throw InputError(s.key_path("action12") + ": the neck has " + std::to_string(frets) +
                             " frets; give action with action_fret in [2, " + std::to_string(frets) + "]");
        return {StringEnd::Form::gap_over_fret, r.quantity(s, "action12", Quantity::length, string_end_mm(10.0)), 12};
    }
    const std::size_t fret = s.count("action_fret", 2, frets);
    return {StringEnd::Form::gap_over_fret, r.quantity(s, "action", Quantity::length, string_end_mm(10.0)), fret};
}

// The string's mass and tension from two of pitch, tension and mu (or the set's unit weight).
void read_string_physics(Reader& r, TomlSection& s, const StringSet* set, std::size_t index, InstrumentString& str) {
    const Range pitch{20.0, 2000.0, false, false, "Hz", 1.0};
    const Range tension{1.0, 1500.0, false, false, "N", 1.0};
    const Range density{0.01, 100.0, false, false, "g/m", 1e-3};
    const auto f = r.optional_quantity(s, "pitch", Quantity::frequency, pitch);
    const auto t = r.optional_quantity(s, "tension", Quantity::force, tension);
    const auto mu = r.optional_quantity(s, "mu", Quantity::linear_density, density);
    const double length = str.scale_length_m;
    std::optional<double> set_mu;
    if (set != nullptr) {
        const StringSetEntry& e = set->strings[index];
        set_mu = e.linear_density;
    }
    const int given = int(f.has_value()) + int(t.has_value()) + int(mu.has_value());
    if (given == 3)
        throw InputError(s.key_path("pitch") + ", tension and mu over-determine the string (f = sqrt(T / mu) / 2L): "
                                               "give two of them, or the pitch with a string set");
    if (given == 2) {
        const TautString taut = !f   ? TautString{length, *t, *mu}
                                : t ? TautString::tuned_with_tension(length, *t, *f)
                                    : TautString::tuned_with_mass(length, *mu, *f);
        str.tension_n = taut.tension_n;
        str.linear_density = taut.linear_density;
        str.frequency_hz = f ? *f : taut.fundamental_hz();
        str.tension_source = t ? "given" : "from the pitch and mu";
    } else if (f && set_mu) {
        str.frequency_hz = *f;
        str.linear_density = *set_mu;
        str.tension_n = TautString::tuned_with_mass(length, *set_mu, *f).tension_n;
        str.tension_source = "string set " + set->name + " (" + set->source + ")";
    } else {
        throw InputError(s.key_path(f ? "tension" : "pitch") +
                         " is missing (required: give two of pitch, tension and mu, or the pitch with strings.set)");
    }
    if (!tension.contains(str.tension_n))
        throw InputError(s.key_path("tension") + ": the pitch and mass give T = " + number_text(str.tension_n) +
                         " N, out of range: must be in " + tension.text());
    if (!pitch.contains(str.frequency_hz))
        throw InputError(s.key_path("pitch") + ": tension and mu give f = " + number_text(str.frequency_hz) +
                         " Hz, out of range: must be in " + pitch.text());
    if (!density.contains(str.linear_density))
        throw InputError(s.key_path("mu") + ": pitch and tension give mu = " + number_text(1e3 * str.linear_density) +
                         " g/m, out of range: must be in " + density.text());
}

void read_stiffness(Reader& r, TomlSection& s, const StringSetEntry* from_set, InstrumentString& str) {
    const int given = int(s.has("B")) + int(s.has("bending_stiffness")) + int(s.has("core"));
    if (given == 0 && from_set != nullptr) {
        str.bending_stiffness = SteelWire{from_set->core_m}.bending_stiffness();  // the set's core
        return;
    }
    if (given != 1)
        throw InputError(s.key_path("core") + (given == 0 ? " is missing (required without a string set: the steel "
                                                            "core's diameter, or B, or bending_stiffness)"
                                                          : ", B and bending_stiffness: give one of them"));
    const double l = str.scale_length_m;
    if (s.has("B")) {
        const double b = Reader::number_in(s, "B", {0.0, 0.01, false, false, "", 1.0});
        str.bending_stiffness = TautString{l, str.tension_n, str.linear_density}.bending_stiffness_for(b);
    } else if (s.has("bending_stiffness")) {
        str.bending_stiffness =
            r.quantity(s, "bending_stiffness", Quantity::bending_stiffness, {0.0, 1.0, false, false, "N m^2", 1.0});
    } else {
        const double d = r.quantity(s, "core", Quantity::length, mm(0.0, 5.0));
        if (str.gauge_m > 0.0 && d > str.gauge_m)
            throw InputError(s.key_path("core") + " is thicker than " + s.key_path("gauge"));
        str.bending_stiffness = SteelWire{d}.bending_stiffness();
    }
}

// The unit a string's gaps are written in (its nut and action values, as read): 64ths of an
// inch, or any fraction of one ("5/64 in", "4.5/64\"", "3/32 in": a gauge's reading),
// thousandths ("0.094 in", "24 thou"), or mm; nothing when it gives no gap.
std::optional<ShopUnits> written_units(TomlSection& s) {
    for (std::string_view key : {"action12", "action", "nut", "saddle_height", "nut_height"}) {
        if (!s.has(key)) continue;
        const toml::node* n = s.node(key);
        const auto* str = n ? n->as_string() : nullptr;
        if (str == nullptr) continue;
        const std::string& text = str->get();
        const bool inches = text.find("in") != std::string::npos || text.find('"') != std::string::npos;
        if (inches && text.find('/') != std::string::npos) return ShopUnits::sixty_fourths;
        if (inches || text.find("thou") != std::string::npos) return ShopUnits::thousandths;
        return ShopUnits::mm;
    }
    return std::nullopt;
}

InstrumentString read_string(Reader& r, TomlSection& s, std::size_t index, double scale, const StringSet* set,
                             std::size_t frets) {
    InstrumentString str;
    str.name = s.text("name");
    if (str.name.empty() || str.name.size() > 16 ||
        !std::all_of(str.name.begin(), str.name.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '#'; }))
        throw InputError(s.key_path("name") + " = \"" + str.name +
                         "\": give 1 to 16 letters or digits (e.g. \"E\", \"A\", \"e\")");
    str.scale_length_m = scale;
    str.gauge_m = r.optional_quantity(s, "gauge", Quantity::length, mm(0.0, 5.0)).value_or(0.0);
    if (str.gauge_m == 0.0 && set != nullptr) str.gauge_m = set->strings[index].gauge_m;
    read_string_physics(r, s, set, index, str);
    read_stiffness(r, s, set != nullptr ? &set->strings[index] : nullptr, str);
    str.nut = read_nut(r, s, s.has("profile"));
    str.bridge = read_bridge_end(r, s, frets, s.has("profile"));
    if (str.bridge.form == StringEnd::Form::gap_over_fret) str.action_fret = str.bridge.fret;
    if (s.has("profile")) {
        const CsvTable table = r.table(s, "profile", 2);
        str.profile_source = s.text("profile");
        str.profile_x_m = table.column(0);
        str.profile_height_m = table.column(1);
        const std::string path = s.key_path("profile") + " = \"" + str.profile_source + "\"";
        for (std::size_t k = 0; k < str.profile_x_m.size(); ++k) {
            const double x = str.profile_x_m[k], g = str.profile_height_m[k];
            if (!(x > 0.0 && x < scale) || (k > 0 && !(x > str.profile_x_m[k - 1])))
                throw InputError(path + ": row " + std::to_string(k + 1) + ": x = " + number_text(x) +
                                 " m must increase and lie inside the string, in (0, " + number_text(scale) + ") m");
            if (!(g <= 0.0 && g >= -0.05))
                throw InputError(path + ": row " + std::to_string(k + 1) + ": height = " + number_text(g) +
                                 " m must be in [-0.05, 0] m (below the open string at rest)");
        }
    }
    s.finish();
    return str;
}

// [neck] scan = "file.csv": columns fret, string (its number, 1 = the first [[string]]),
// height (the header says the unit: height_mm or height_in).
void read_scan(Reader& r, TomlSection& neck, Instrument& inst) {
    if (!neck.has("scan")) return;
    const CsvTable table = r.table(neck, "scan", 3);
    const std::string path = neck.key_path("scan") + " = \"" + neck.text("scan") + "\"";
    double factor = 0.0;
    if (table.column_names.size() >= 3) {
        if (table.column_names[2] == "height_mm") factor = 1e-3;
        if (table.column_names[2] == "height_in") factor = 0.0254;
    }
    if (factor == 0.0)
        throw InputError(path + ": the header must name the columns fret,string,height_mm (or height_in)");
    for (std::size_t k = 0; k < table.row_count(); ++k) {
        const auto& row = table.rows[k];
        const std::string at = path + " row " + std::to_string(k + 1);
        const double fret = row[0], string = row[1], h = row[2] * factor;
        if (!(fret == std::floor(fret) && fret >= 1 && fret <= static_cast<double>(inst.neck.fret_count)))
            throw InputError(at + ": fret " + number_text(fret) + " does not exist (frets 1 to " +
                             std::to_string(inst.neck.fret_count) + ")");
        if (!(string == std::floor(string) && string >= 1 && string <= static_cast<double>(inst.strings.size())))
            throw InputError(at + ": string " + number_text(string) + " does not exist (strings 1 to " +
                             std::to_string(inst.strings.size()) + ", in the file's order)");
        if (!(std::abs(h) <= 5e-3)) throw InputError(at + ": height " + number_text(h * 1e3) + " mm: must be in [-5, 5] mm");
        inst.strings[static_cast<std::size_t>(string) - 1].scan_m[static_cast<std::size_t>(fret)] = h;
    }
    for (const InstrumentString& s : inst.strings)
        if (!s.scan_m.empty() && s.scan_m.size() != inst.neck.fret_count)
            throw InputError(path + ": string " + s.name + " has " + std::to_string(s.scan_m.size()) + " of its " +
                             std::to_string(inst.neck.fret_count) + " frets: a scan gives every fret of a string");
}

// The attack keys given in `s`, over what `a` holds (the style's defaults). With `every`, each
// key must be there (a style's defaults file).
void read_attack_keys(Reader& r, TomlSection& s, double shortest, AttackSettings& a, bool every) {
    const Range where = mm(0.0, 0.5 * shortest * 1e3, true, true);
    const Range pad = mm(0.0, 50.0);
    const Range amplitude = mm(0.0, 10.0);
    const Range degrees = {0.0, 90.0, false, false, "degrees", 1.0};
    const auto length = [&](std::string_view key, const Range& range, double& value) {
        if (every || s.has(key)) value = r.quantity(s, key, Quantity::length, range);
    };
    const auto number = [&](std::string_view key, const Range& range, double& value) {
        if (every || s.has(key)) value = Reader::number_in(s, key, range);
    };
    length("position", where, a.finger.from_bridge_m);
    length("finger_width", pad, a.finger.width_m);
    number("angle", degrees, a.finger.angle_deg);
    length("soft", amplitude, a.soft_m);
    length("medium", amplitude, a.medium_m);
    length("hard", amplitude, a.hard_m);
    length("position_spread", mm(0.0, 50.0, false, false), a.position_spread_m);
    number("angle_spread", {0.0, 45.0, false, false, "degrees", 1.0}, a.angle_spread_deg);
    number("strength_spread", {0.0, 0.9, false, false, "", 1.0}, a.strength_spread);
    length("pop", amplitude, a.pop_m);
    length("pop_position", where, a.pop.from_bridge_m);
    length("pop_width", pad, a.pop.width_m);
    if (every || s.has("slap"))
        a.slap_m_per_s = r.quantity(s, "slap", Quantity::velocity, {0.0, 10.0, true, false, "m/s", 1.0});
    length("slap_position", where, a.slap.from_bridge_m);
    length("slap_width", pad, a.slap.width_m);
    if (every || s.has("thumb_mass"))
        a.thumb_mass_kg = r.quantity(s, "thumb_mass", Quantity::mass, {0.0, 200.0, true, false, "g", 1e-3});
    number("thumb_stiffness", {0.0, 1e8, true, false, "N/m", 1.0}, a.thumb_stiffness);
    number("thumb_loss", {0.0, 1000.0, false, false, "s/m", 1.0}, a.thumb_loss);
    length("pick", amplitude, a.pick_m);
    length("pick_position", where, a.pick.from_bridge_m);
    length("pick_width", pad, a.pick.width_m);
    number("pick_angle", degrees, a.pick.angle_deg);
    if (const auto n = s.optional_count("ensemble", 1, 200)) a.ensemble = *n;
    if (const auto seed = s.optional_count("seed", 0, std::size_t{1} << 52)) a.seed = *seed;
    if (!(a.soft_m < a.medium_m && a.medium_m < a.hard_m))
        throw InputError(s.key_path("medium") + ": the finger plucks must grow: soft (" + number_text(a.soft_m * 1e3) +
                         " mm) < medium (" + number_text(a.medium_m * 1e3) + " mm) < hard (" +
                         number_text(a.hard_m * 1e3) + " mm)");
}

// A style's built-in defaults, cases/FOLDER/STYLE.toml, parsed.
toml::table style_defaults(const std::string& folder, const std::string& style) {
    const std::string file = folder + "/" + style + ".toml";
    const auto text = find_builtin_file(file);
    if (!text) throw std::logic_error("the built-in " + file + " is missing");
    return parse_toml_document(*text, file);
}

// The attacks: the style's defaults (cases/attacks/STYLE.toml: a bass's when the lowest
// string sounds below 60 Hz or a scale reaches 0.75 m, else a guitar's), then the file's own
// [attack] keys over them.
void read_attack(Reader& r, std::optional<TomlSection> s, double shortest, Instrument& inst) {
    AttackSettings& a = inst.attack;
    double lowest = inst.strings.front().frequency_hz, longest = 0.0;
    for (const InstrumentString& string : inst.strings) {
        lowest = std::min(lowest, string.frequency_hz);
        longest = std::max(longest, string.scale_length_m);
    }
    std::string style = lowest < 60.0 || longest >= 0.75 ? "bass" : "guitar";
    if (s) {
        if (auto given = s->optional_text("style")) {
            if (*given != "bass" && *given != "guitar")
                throw InputError(s->key_path("style") + " = \"" + *given + "\": must be \"bass\" or \"guitar\" (whose "
                                 "default attacks, cases/attacks/)");
            style = *given;
        }
    }
    const toml::table defaults = style_defaults("attacks", style);
    TomlSection d(defaults, "attack");
    d.text("style");
    read_attack_keys(r, d, shortest, a, true);
    d.finish();
    a.style = style;
    a.slap.angle_deg = 90.0;
    a.pop.angle_deg = -90.0;
    if (s) {
        read_attack_keys(r, *s, shortest, a, false);
        s->finish();
    }
}

}  // namespace

bool listens_through_rig(const std::string& word, const std::string& key) {
    if (word == "rig") return true;
    if (word == "pickup") return false;
    throw InputError(key + " = \"" + word + "\": must be \"rig\" (through the pickup's circuit and a cabinet) or "
                     "\"pickup\" (its full range)");
}

double checked_partial_scatter(double cents, const std::string& key) {
    if (!(cents >= 0.0 && cents <= kMostPartialScatterCents))
        throw InputError(out_of_range_message(key + " (cents)", cents,
                                              "must be in [0, " + number_text(kMostPartialScatterCents) + "]"));
    return cents;
}

namespace {

// The rig the bench hears through: the style's figures (cases/rigs/STYLE.toml, the same
// style as the attacks'), then the file's own [rig] keys over them.
void read_rig_keys(Reader& r, TomlSection& t, BenchSettings& b) {
    RigSettings& g = b.rig;
    PickupCircuit& p = g.pickup;
    if (const auto listen = t.optional_text("listen")) b.listen_through_rig = listens_through_rig(*listen, t.key_path("listen"));
    if (t.has("pickup_inductance_h"))
        p.inductance_h = Reader::number_in(t, "pickup_inductance_h", {0.01, 100.0, false, false, "H", 1.0});
    if (t.has("pickup_resistance_ohm"))
        p.resistance_ohm = Reader::number_in(t, "pickup_resistance_ohm", {1.0, 1e6, false, false, "ohm", 1.0});
    if (t.has("capacitance_pf"))
        p.capacitance_f = 1e-12 * Reader::number_in(t, "capacitance_pf", {1.0, 1e5, false, false, "pF", 1.0});
    if (t.has("load_kohm")) p.load_ohm = 1e3 * Reader::number_in(t, "load_kohm", {1.0, 1e5, false, false, "kohm", 1.0});
    if (const auto f = r.optional_quantity(t, "speaker_high", Quantity::frequency, {0.5, 40.0, false, false, "kHz", 1e3}))
        g.speaker_high_hz = *f;
    if (const auto n = t.optional_count("speaker_order", 1, 8)) g.speaker_order = static_cast<int>(*n);
    if (const auto f = r.optional_quantity(t, "speaker_low", Quantity::frequency, {1.0, 500.0, false, false, "Hz", 1.0}))
        g.speaker_low_hz = *f;
    if (!(g.speaker_low_hz < g.speaker_high_hz))
        throw InputError(t.key_path("speaker_low") + " must lie below " + t.key_path("speaker_high"));
}

void read_rig(Reader& r, std::optional<TomlSection> s, Instrument& inst) {
    const toml::table defaults = style_defaults("rigs", inst.attack.style);
    TomlSection d(defaults, "rig");
    read_rig_keys(r, d, inst.bench);
    d.finish();
    if (s) {
        read_rig_keys(r, *s, inst.bench);
        s->finish();
    }
}

void read_adjusters(Reader& r, std::optional<TomlSection> s, Instrument& inst) {
    if (!s) return;
    Adjusters& a = inst.adjusters;
    a.truss_rod_turn_m = r.optional_quantity(*s, "truss_rod_turn", Quantity::length, mm(0.0, 2.0)).value_or(0.0);
    a.saddle_screw_pitch_m = r.optional_quantity(*s, "saddle_screw_pitch", Quantity::length, mm(0.0, 2.0)).value_or(0.0);
    s->finish();
}

void read_simulation(Reader& r, std::optional<TomlSection> s, double shortest, Instrument& inst) {
    BenchSettings& b = inst.bench;
    const toml::table empty;
    TomlSection none(empty, "simulation");
    TomlSection& t = s ? *s : none;
    b.sample_rate_hz = r.optional_quantity(t, "fs", Quantity::frequency, {50.0, 20000.0, false, false, "kHz", 1e3})
                           .value_or(1e6);
    b.duration_s =
        r.optional_quantity(t, "duration", Quantity::time, {0.01, 5.0, false, false, "s", 1.0}).value_or(0.3);
    b.grid_step_m = r.optional_quantity(t, "grid_step", Quantity::length, mm(0.1, 10.0, false, false)).value_or(1e-3);
    b.output_rate_hz = r.optional_quantity(t, "output_rate", Quantity::frequency,
                                           {8.0, 192.0, false, false, "kHz", 1e3})
                           .value_or(48000.0);
    if (b.output_rate_hz > b.sample_rate_hz)
        throw InputError(t.key_path("output_rate") + " must not exceed " + t.key_path("fs"));
    b.observe_from_bridge_m =
        r.optional_quantity(t, "observe", Quantity::length, mm(0.0, 0.5 * shortest * 1e3, true, true)).value_or(9e-3);
    if (t.has("buzz_band"))
        throw InputError(t.key_path("buzz_band") + ": the bench no longer judges buzz by a frequency band; it listens "
                         "(simulation.listening_level, simulation.audible: docs/setup.md, \"What is heard\")");
    b.listening_level_db_spl = t.has("listening_level")
                                   ? Reader::number_in(t, "listening_level", {40.0, 120.0, false, false, "dB SPL", 1.0})
                                   : 85.0;
    b.audible_db = t.has("audible") ? Reader::number_in(t, "audible", {-40.0, 40.0, false, false, "dB", 1.0}) : 0.0;
    b.partial_scatter_cents =
        t.has("partial_scatter") ? checked_partial_scatter(t.number("partial_scatter"), t.key_path("partial_scatter")) : 0.0;
    b.fret_friction = t.has("fret_friction") ? Reader::number_in(t, "fret_friction", {0.0, 2.0, false, false, "", 1.0}) : 0.0;
    if (const auto stops = t.optional_text("stopped_modes")) {
        if (*stops != "held" && *stops != "pinned")
            throw InputError(t.key_path("stopped_modes") + " = \"" + *stops +
                             "\": must be \"held\" (the string held on the fret) or \"pinned\" (pinned at the fret)");
        b.pinned_stops = *stops == "pinned";
    }
    if (s) s->finish();
}

void read_physics_tables(Reader& r, TomlSection& top, Instrument& inst) {
    BenchSettings& b = inst.bench;
    // The damping law fitted to the paper's bass string (cases/bass-neck.toml) unless given.
    b.damping_eta0 = 0.711;
    b.damping_eta2 = 2.99e-4;
    if (auto d = top.optional_section("damping")) {
        b.damping_eta0 = r.quantity(*d, "eta0", Quantity::rate, {0.0, 100.0, false, false, "1/s", 1.0});
        b.damping_eta2 = r.quantity(*d, "eta2", Quantity::diffusivity, {0.0, 0.01, false, false, "m^2/s", 1.0});
        d->finish();
    }
    if (auto c = top.optional_section("contact")) {
        b.contact_stiffness = Reader::number_in(*c, "K", {0.0, 1e16, true, false, "N/m^(alpha+1)", 1.0});
        b.contact_exponent = Reader::number_in(*c, "alpha", {1.0, 3.0, false, false, "", 1.0});
        b.contact_law = contact_law_named(c->optional_text("law").value_or("penalty"), c->key_path("law"));
        if (c->has("restitution")) {  // e = 0 unless given
            if (b.contact_law != ContactLawKind::impact)
                throw InputError(c->key_path("restitution") + " needs " + c->key_path("law") + " = \"impact\"");
            b.restitution = Reader::number_in(*c, "restitution", {0.0, 1.0, false, false, "", 1.0});
        }
        c->finish();
    }
}

// The pull the strings put on the neck as the file tunes them (the relief was measured under
// it), and a warning for a string whose mass does not fit its gauge (NeckBeam.hpp,
// SteelWire.hpp).
void note_string_loads(const std::vector<TomlSection>& tables, Instrument& inst) {
    double pull = 0.0;
    for (const InstrumentString& str : inst.strings) pull += str.tension_n;
    inst.neck.relief_pull_n = pull;
    for (std::size_t k = 0; k < inst.strings.size(); ++k) {
        const InstrumentString& str = inst.strings[k];
        const SteelWire rod{str.gauge_m};
        if (str.gauge_m <= 0.0 || rod.plausible_fill(str.linear_density)) continue;
        std::ostringstream w;
        w.precision(3);
        w << tables[k].key_path("mu") << ": " << str.name << " weighs " << 1e3 * str.linear_density << " g/m ("
          << str.tension_source << "), " << rod.fill(str.linear_density) << " times a steel rod of its gauge "
          << 1e3 * str.gauge_m << " mm (strings weigh " << SteelWire::kPlausibleFillLow << " to "
          << SteelWire::kPlausibleFillHigh << " times it): at " << str.frequency_hz << " Hz that is a tension of "
          << str.tension_n << " N; check the unit weight, the tension and the gauge";
        inst.warnings.push_back(w.str());
    }
}

}  // namespace

std::size_t Instrument::string_index(const std::string& wanted) const {
    std::string names;
    for (std::size_t k = 0; k < strings.size(); ++k) {
        if (strings[k].name == wanted) return k;
        names += (k ? ", " : "") + strings[k].name;
    }
    throw InputError("string \"" + wanted + "\" is not on " + name + " (its strings: " + names + ")");
}

Instrument parse_instrument(std::string_view text, const std::string& source_name, const DataSource& data) {
    const toml::table root = parse_toml_document(text, source_name);
    TomlSection top(root, "");
    if (top.has("obstacle") || top.has("excitation"))
        throw InputError(source_name + " is a case file (it has [obstacle] or [excitation]), not an instrument file: "
                                       "`fretbuzz setup` takes an instrument (docs/instrument-format.md), e.g. the "
                                       "built-in jazz-bass, electric-guitar, bass-5 or bass-neck");
    Reader r(data);
    Instrument inst;
    inst.source_text = std::string(text);
    inst.name = top.text("name");
    check_instrument_name(inst.name, top.key_path("name"));
    inst.description = top.optional_text("description").value_or("");
    std::vector<TomlSection> string_tables = top.sections("string");
    if (string_tables.empty() || string_tables.size() > kMaxStrings)
        throw InputError(out_of_range_message("string (the number of [[string]] tables)",
                                              static_cast<double>(string_tables.size()),
                                              "must be in [1, " + std::to_string(kMaxStrings) + "]"));
    std::vector<double> scales;
    TomlSection neck = top.section("neck");
    read_with_key_check(neck, [&] { read_neck(r, neck, string_tables.size(), inst, scales); });
    const std::vector<double> scale_of = string_scales(scales, string_tables.size());
    const StringSet* set = nullptr;
    if (auto strings = top.optional_section("strings")) {
        set = &builtin_string_set(strings->text("set"), strings->key_path("set"));
        if (set->strings.size() != string_tables.size())
            throw InputError(strings->key_path("set") + " = \"" + set->name + "\" has " +
                             std::to_string(set->strings.size()) + " strings; the instrument has " +
                             std::to_string(string_tables.size()));
        strings->finish();
    }
    std::set<std::string> names;
    bool units_known = false;
    for (std::size_t k = 0; k < string_tables.size(); ++k) {
        inst.strings.push_back(read_with_key_check(
            string_tables[k], [&] { return read_string(r, string_tables[k], k, scale_of[k], set, inst.neck.fret_count); }));
        if (!units_known)
            if (const auto units = written_units(string_tables[k])) {
                inst.units = *units;
                units_known = true;
            }
        if (!names.insert(inst.strings.back().name).second)
            throw InputError(string_tables[k].key_path("name") + " = \"" + inst.strings.back().name +
                             "\": another string has that name; names must differ");
    }
    read_scan(r, neck, inst);
    neck.finish();
    const double shortest = *std::min_element(scales.begin(), scales.end());
    read_with_key_check(top, [&] {
        read_attack(r, top.optional_section("attack"), shortest, inst);
        read_physics_tables(r, top, inst);
        read_simulation(r, top.optional_section("simulation"), shortest, inst);
        read_rig(r, top.optional_section("rig"), inst);
        read_adjusters(r, top.optional_section("adjusters"), inst);
    });
    note_string_loads(string_tables, inst);
    const AttackSettings& a = inst.attack;
    for (const GestureSettings* g : {&a.finger, &a.pick, &a.pop, &a.slap})
        if (inst.bench.observe_from_bridge_m >= g->from_bridge_m - 0.5 * g->width_m)
            throw InputError("simulation.observe (" + number_text(inst.bench.observe_from_bridge_m * 1e3) +
                             " mm from the bridge) must lie between the bridge and every attack's place (attack.position, "
                             "pop_position, slap_position, pick_position, less half their widths)");
    top.finish();
    return inst;
}

std::set<std::string> instrument_keys_looked_up(std::string_view text, const std::string& source_name,
                                                const DataSource& data) {
    string_sets();  // read apart: their keys are not an instrument's
    std::set<std::string> keys;
    KeyLogScope log(keys);
    parse_instrument(text, source_name, data);
    return keys;
}

std::vector<BuiltinInstrumentInfo> builtin_instruments() {
    std::vector<BuiltinInstrumentInfo> list;
    for (const EmbeddedFile& f : builtin_files()) {
        std::string_view name = f.name;
        if (!name.starts_with(kInstrumentDir) || !name.ends_with(kSuffix)) continue;
        name.remove_prefix(kInstrumentDir.size());
        name.remove_suffix(kSuffix.size());
        if (name.find('/') != std::string_view::npos) continue;
        const toml::table root = parse_toml_document(f.text(), std::string(f.name));
        list.push_back({std::string(name), root["description"].value_or(std::string())});
    }
    return list;
}

bool is_builtin_instrument(std::string_view name) {
    return find_builtin_file(std::string(kInstrumentDir) + std::string(name) + std::string(kSuffix)).has_value();
}

Instrument load_instrument(const std::string& name_or_path) {
    if (auto text = find_builtin_file(std::string(kInstrumentDir) + name_or_path + std::string(kSuffix)))
        return parse_instrument(*text, name_or_path, DataSource::builtin());
    const std::filesystem::path path(name_or_path);
    if (path.extension() == kSuffix)
        return parse_instrument(read_text_file(path, "instrument file " + path.string(), kMaxCaseFileBytes),
                                path.string(), DataSource::directory(path.parent_path()));
    std::string names;
    for (const auto& info : builtin_instruments()) names += (names.empty() ? "" : ", ") + info.name;
    throw InputError("unknown instrument '" + name_or_path + "': give a built-in instrument (" + names +
                     ") or the path of an instrument file (.toml)");
}

std::vector<StringSet> builtin_string_sets() { return string_sets(); }

const StringSet& builtin_string_set(const std::string& name, const std::string& key) {
    const std::vector<StringSet>& sets = string_sets();
    for (const StringSet& s : sets)
        if (s.name == name) return s;
    std::string names;
    for (const StringSet& s : sets) names += (names.empty() ? "" : ", ") + s.name;
    throw InputError(key + " = \"" + name + "\": no such string set (known: " + names + ")");
}

std::optional<std::string> builtin_instrument_text(std::string_view name) {
    if (name.find('/') != std::string_view::npos) return std::nullopt;
    if (auto text = find_builtin_file(std::string(kInstrumentDir) + std::string(name) + std::string(kSuffix)))
        return std::string(*text);
    return std::nullopt;
}

namespace {

std::vector<StringSet> read_string_sets() {
    const auto text = find_builtin_file(std::string(kSetsFile));
    if (!text) return {};
    const toml::table root = parse_toml_document(*text, std::string(kSetsFile));
    std::vector<StringSet> sets;
    for (const auto& [key, node] : root) {
        const auto* table = node.as_table();
        if (table == nullptr) continue;
        TomlSection s(*table, std::string(key.str()));
        StringSet set;
        set.name = std::string(key.str());
        set.description = s.text("description");
        set.source = s.text("source");
        set.scale_length_m = Reader::checked(*s.node("scale"), s.key_path("scale"), Quantity::length,
                                             {0.2, 1.5, false, false, "m", 1.0});
        set.core_ratio = Reader::number_in(s, "core_ratio", {0.1, 0.9, false, false, "", 1.0});
        for (TomlSection e : s.sections("strings")) {
            StringSetEntry entry;
            entry.gauge_m = Reader::checked(*e.node("gauge"), e.key_path("gauge"), Quantity::length, mm(0.0, 5.0));
            entry.frequency_hz = Reader::checked(*e.node("pitch"), e.key_path("pitch"), Quantity::frequency,
                                                 {20.0, 2000.0, false, false, "Hz", 1.0});
            entry.tension_n = Reader::checked(*e.node("tension"), e.key_path("tension"), Quantity::force,
                                              {1.0, 1500.0, false, false, "N", 1.0});
            if (const toml::node* uw = e.node("unit_weight"))
                entry.unit_weight = Reader::checked(*uw, e.key_path("unit_weight"), Quantity::linear_density,
                                                    {0.01, 100.0, false, false, "g/m", 1e-3});
            entry.linear_density =
                TautString::tuned_with_tension(set.scale_length_m, entry.tension_n, entry.frequency_hz).linear_density;
            entry.plain = e.optional_flag("plain").value_or(false);
            entry.core_m = entry.plain ? entry.gauge_m : set.core_ratio * entry.gauge_m;
            e.finish();
            set.strings.push_back(entry);
        }
        s.finish();
        sets.push_back(std::move(set));
    }
    return sets;
}

}  // namespace

}  // namespace fretbuzz
