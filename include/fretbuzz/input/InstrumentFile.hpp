#pragma once
// Instrument files: one TOML file describes an instrument on the set-up bench (its neck,
// its strings and how they lie over the frets, how it is played, how finely it is
// simulated); docs/instrument-format.md gives every key with its unit and range. Built-in
// instruments are such files, compiled in from cases/instruments/. Every value is checked
// as it is read: an InputError names the key and its allowed range.
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/Instrument.hpp"

namespace fretbuzz {

struct BuiltinInstrumentInfo {
    std::string name;
    std::string description;
};

std::vector<BuiltinInstrumentInfo> builtin_instruments();
bool is_builtin_instrument(std::string_view name);

// Reads an instrument file's text; data files (a neck profile, a fret scan) come from `data`.
Instrument parse_instrument(std::string_view toml_text, const std::string& source_name, const DataSource& data);
// The key paths (array indices dropped: "string.nut") that reading this text looks up,
// present or not: the schema as the reader enforces it (its documentation is tested against it).
std::set<std::string> instrument_keys_looked_up(std::string_view toml_text, const std::string& source_name,
                                                const DataSource& data);
// A built-in instrument's name, or the path of an instrument file (.toml). InputError lists
// the built-in names when it is neither, and says so when the file is a case file.
Instrument load_instrument(const std::string& name_or_path);

// A named string set with the tensions its maker publishes (cases/strings/sets.toml):
// gauges and tensions at a reference pitch and scale, giving each string's unit weight, and
// the core each string bends on.
struct StringSetEntry {
    double gauge_m = 0.0;
    double frequency_hz = 0.0;  // the pitch the tension is published for
    double tension_n = 0.0;
    double linear_density = 0.0;  // kg/m: mu = T / (2 L f)^2 at the set's scale
    std::optional<double> unit_weight;  // kg/m, the maker's, where the chart gives it
    bool plain = false;         // a plain steel wire (else wound on a core)
    double core_m = 0.0;        // the steel it bends on: the gauge if plain, else core_ratio times it
};
struct StringSet {
    std::string name;
    std::string description;
    std::string source;          // the publication the tensions come from
    double scale_length_m = 0.0;  // the scale they are published for
    double core_ratio = 0.0;     // a wound string's core diameter over its gauge
    std::vector<StringSetEntry> strings;  // low to high
};
std::vector<StringSet> builtin_string_sets();
// The set of that name; InputError naming `key` and listing the sets if there is none.
const StringSet& builtin_string_set(const std::string& name, const std::string& key);

// A built-in instrument's file, to copy and edit (`fretbuzz show`); nothing if there is none.
std::optional<std::string> builtin_instrument_text(std::string_view name);

}  // namespace fretbuzz
