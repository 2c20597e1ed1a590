#include "fretbuzz/input/InstrumentUnits.hpp"

#include <array>
#include <charconv>
#include <cstdio>
#include <cmath>
#include <optional>
#include <span>
#include <utility>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/TextFile.hpp"

namespace fretbuzz {

namespace {

constexpr double kInch = 0.0254;               // m
constexpr double kPoundForce = 4.4482216152605;  // N
constexpr double kPound = 0.45359237;           // kg

struct Unit {
    std::string_view name;
    double factor;  // to SI
};

std::span<const Unit> units_of(Quantity kind) {
    static constexpr std::array length{Unit{"m", 1.0}, Unit{"cm", 1e-2}, Unit{"mm", 1e-3}, Unit{"in", kInch},
                                       Unit{"thou", kInch * 1e-3}};
    static constexpr std::array force{Unit{"N", 1.0}, Unit{"lb", kPoundForce}};
    static constexpr std::array frequency{Unit{"Hz", 1.0}, Unit{"kHz", 1e3}, Unit{"MHz", 1e6}};
    static constexpr std::array density{Unit{"kg/m", 1.0}, Unit{"g/m", 1e-3}, Unit{"lb/in", kPound / kInch}};
    static constexpr std::array stiffness{Unit{"N m^2", 1.0}, Unit{"N*m^2", 1.0}};
    static constexpr std::array velocity{Unit{"m/s", 1.0}};
    static constexpr std::array rate{Unit{"1/s", 1.0}};
    static constexpr std::array diffusivity{Unit{"m^2/s", 1.0}};
    static constexpr std::array time{Unit{"s", 1.0}, Unit{"ms", 1e-3}};
    static constexpr std::array mass{Unit{"kg", 1.0}, Unit{"g", 1e-3}};
    switch (kind) {
        case Quantity::length: return length;
        case Quantity::force: return force;
        case Quantity::frequency: return frequency;
        case Quantity::linear_density: return density;
        case Quantity::bending_stiffness: return stiffness;
        case Quantity::velocity: return velocity;
        case Quantity::rate: return rate;
        case Quantity::diffusivity: return diffusivity;
        case Quantity::time: return time;
        case Quantity::mass: return mass;
    }
    return {};
}

// A decimal number at the start of s; advances s past it.
std::optional<double> leading_number(std::string_view& s) {
    double v = 0.0;
    const char* first = s.data();
    if (!s.empty() && s.front() == '+') ++first;
    const auto [end, error] = std::from_chars(first, s.data() + s.size(), v);
    if (error != std::errc() || end == first) return std::nullopt;
    s.remove_prefix(static_cast<std::size_t>(end - s.data()));
    return v;
}

// "2.4", "5/64", "3/32", "4.5/64", "1 3/16" at the start of s (fractions in any whole
// denominator and mixed numbers as luthiers write inches: a half 64th is "4.5/64").
std::optional<double> leading_value(std::string_view& s) {
    std::string_view rest = s;
    auto a = leading_number(rest);
    if (!a) return std::nullopt;
    double value = *a;
    std::string_view after = trim_blanks(rest);
    if (!rest.empty() && rest.front() == '/') {  // a fraction a/b: b whole
        rest.remove_prefix(1);
        const auto b = leading_number(rest);
        if (!b || !(*b > 0.0) || *b != std::floor(*b)) return std::nullopt;
        value = *a / *b;
    } else if (*a == std::floor(*a) && *a >= 0.0 && !after.empty() && after.front() >= '0' && after.front() <= '9') {
        // A whole number then a fraction: "1 3/16".
        std::string_view frac = after;
        const auto n = leading_number(frac);
        if (n && !frac.empty() && frac.front() == '/') {
            frac.remove_prefix(1);
            const auto d = leading_number(frac);
            if (d && *d > 0.0 && *n == std::floor(*n) && *d == std::floor(*d) && *n < *d) {
                value = *a + *n / *d;
                rest = frac;
            }
        }
    }
    s = rest;
    return value;
}

std::string example(Quantity kind) {
    switch (kind) {
        case Quantity::length:
            return "\"2.4 mm\", \"0.094 in\", \"5/64 in\", \"3/32 in\", \"4.5/64 in\", \"1 3/16 in\", '5/64\"', \"12 thou\"";
        case Quantity::force: return "\"191.6 N\" or \"43.1 lb\"";
        case Quantity::frequency: return "\"98 Hz\" or a note such as \"G2\"";
        case Quantity::linear_density: return "\"6.69 g/m\" or \"0.000374 lb/in\"";
        case Quantity::bending_stiffness: return "\"5.24e-4 N m^2\"";
        case Quantity::velocity: return "\"1.5 m/s\"";
        case Quantity::rate: return "\"0.711 1/s\"";
        case Quantity::diffusivity: return "\"2.99e-4 m^2/s\"";
        case Quantity::time: return "\"0.3 s\" or \"300 ms\"";
        case Quantity::mass: return "\"20 g\"";
    }
    return {};
}

// A value read: in SI units, the number as typed and the name of the unit it was read in.
struct Parsed {
    double si = 0.0;
    std::string_view number, unit;
};

Parsed parse(std::string_view text, Quantity kind, std::optional<std::string_view> default_unit,
             const std::string& key) {
    const std::string_view whole = trim_blanks(text);
    const auto refuse = [&](const std::string& why) -> Parsed {
        throw InputError(key + " = \"" + std::string(text) + "\": " + why + " (e.g. " + example(kind) +
                         "; units: " + unit_names(kind) + ")");
    };
    if (kind == Quantity::frequency && !whole.empty() && whole.front() >= 'A' && whole.front() <= 'G')
        return {note_frequency(whole, key), whole, "Hz"};
    std::string_view rest = whole;
    const auto value = leading_value(rest);
    if (!value) return refuse("not a number with its unit");
    const std::string_view number = trim_blanks(whole.substr(0, whole.size() - rest.size()));
    const std::string_view written = trim_blanks(rest);
    const std::string_view unit = written.empty() ? default_unit.value_or("") : written == "\"" && kind == Quantity::length
                                                                                  ? std::string_view("in")  // 5/64"
                                                                                  : written;
    if (unit.empty()) return refuse("say its unit");
    double factor = 0.0;
    for (const Unit& u : units_of(kind))
        if (u.name == unit) factor = u.factor;
    if (factor == 0.0) return refuse("unknown unit \"" + std::string(unit) + "\"");
    const double si = *value * factor;
    if (!std::isfinite(si)) return refuse("not a finite number");
    return {si, number, unit};
}

}  // namespace

std::string unit_names(Quantity kind) {
    std::string names;
    const auto list = units_of(kind);
    for (std::size_t k = 0; k < list.size(); ++k) {
        if (kind == Quantity::bending_stiffness && k > 0) break;  // one spelling is enough to name
        names += (k == 0 ? "" : (k + 1 == list.size() ? " or " : ", ")) + std::string(list[k].name);
    }
    return names;
}

double parse_quantity(std::string_view text, Quantity kind, const std::string& key) {
    return parse(text, kind, std::nullopt, key).si;
}

double parse_quantity_or(std::string_view text, Quantity kind, std::string_view default_unit, const std::string& key) {
    return parse(text, kind, default_unit, key).si;
}

LengthAsRead read_length(std::string_view text, std::string_view bare_unit, const std::string& key) {
    const Parsed p = parse(text, Quantity::length, bare_unit, key);
    std::string as_read = std::string(p.number) + " " + std::string(p.unit);
    if (p.unit != "mm") {
        char mm[48];
        std::snprintf(mm, sizeof mm, " (%.3f mm)", p.si * 1e3);
        as_read += mm;
    }
    return {p.si, as_read};
}

std::size_t whole_number(std::string_view text, const std::string& option, std::size_t low, std::size_t high,
                         const std::string& what) {
    std::size_t v = 0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (error != std::errc() || end != text.data() + text.size() || text.empty() || v < low || v > high)
        throw InputError(option + " " + std::string(text) + ": " + what + " must be a whole number in [" +
                         std::to_string(low) + ", " + std::to_string(high) + "]");
    return v;
}

double screw_turns(std::string_view text, const std::string& option, double most) {
    const auto refuse = [&]() -> double {
        throw InputError(option + " " + std::string(text) + ": turns must be a number or a fraction (+0.25, -1/2, " +
                         "3/4 turn; + clockwise) in [" + number_text(-most) + ", " + number_text(most) + "]");
    };
    std::string_view s = text;
    const auto trim = [&s] {
        while (!s.empty() && s.back() == ' ') s.remove_suffix(1);
        while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
    };
    trim();
    for (std::string_view word : {"turns", "turn"})
        if (s.ends_with(word)) {
            s.remove_suffix(word.size());
            break;
        }
    trim();
    double sign = 1.0;
    if (!s.empty() && (s.front() == '+' || s.front() == '-')) {
        sign = s.front() == '-' ? -1.0 : 1.0;
        s.remove_prefix(1);
    }
    const auto number = [&refuse](std::string_view t) {
        double v = 0.0;
        const auto [end, error] = std::from_chars(t.data(), t.data() + t.size(), v);
        if (t.empty() || t.front() == '+' || t.front() == '-' || error != std::errc() || end != t.data() + t.size())
            return refuse();
        return v;
    };
    double value = 0.0;
    if (const std::size_t slash = s.find('/'); slash != std::string_view::npos) {
        const double below = number(s.substr(slash + 1));
        if (!(below > 0.0)) return refuse();
        value = number(s.substr(0, slash)) / below;
    } else {
        value = number(s);
    }
    value *= sign;
    if (!std::isfinite(value) || std::abs(value) > most) return refuse();
    return value;
}

double note_frequency(std::string_view name, const std::string& key) {
    static constexpr std::array<std::pair<char, int>, 7> letters{
        {{'C', 0}, {'D', 2}, {'E', 4}, {'F', 5}, {'G', 7}, {'A', 9}, {'B', 11}}};
    const auto refuse = [&]() -> double {
        throw InputError(key + " = \"" + std::string(name) +
                         "\": not a note; give a letter A-G, an optional # or b, and an octave in [0, 8] "
                         "(E1 = 41.2 Hz, A4 = 440 Hz) or a frequency such as \"98 Hz\"");
    };
    std::string_view s = name;
    if (s.empty()) return refuse();
    int semitone = -1;
    for (const auto& [letter, offset] : letters)
        if (s.front() == letter) semitone = offset;
    if (semitone < 0) return refuse();
    s.remove_prefix(1);
    if (!s.empty() && (s.front() == '#' || s.front() == 'b')) {
        semitone += s.front() == '#' ? 1 : -1;
        s.remove_prefix(1);
    }
    if (s.size() != 1 || s.front() < '0' || s.front() > '8') return refuse();
    const int octave = s.front() - '0';
    const int midi = 12 * (octave + 1) + semitone;
    return 440.0 * std::exp2((midi - 69) / 12.0);
}

}  // namespace fretbuzz
