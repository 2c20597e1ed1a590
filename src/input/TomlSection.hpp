#pragma once
// Strict reading of one table of a case file: every value is checked for type and
// finiteness, and finish() rejects any key nobody asked for, so a typo is an error
// that names the key instead of a silent fall-back to a default.
#include <array>
#include <cstddef>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

namespace fretbuzz {

// Parses TOML text; a syntax error becomes an InputError "source:line:column: what".
toml::table parse_toml_document(std::string_view text, const std::string& source);

// While alive, every key path a TomlSection looks up on this thread (present or not, array
// indices dropped: "obstacle.type") is added to `log`: the schema as the parser enforces it.
class KeyLogScope {
public:
    explicit KeyLogScope(std::set<std::string>& log);
    ~KeyLogScope();
    KeyLogScope(const KeyLogScope&) = delete;
    KeyLogScope& operator=(const KeyLogScope&) = delete;

private:
    std::set<std::string>* previous_;
};

class TomlSection {
public:
    TomlSection(const toml::table& table, std::string path);

    const std::string& path() const { return path_; }
    std::string key_path(std::string_view key) const;
    bool has(std::string_view key) const;
    // The table's keys, in its order (not logged as looked up).
    std::vector<std::string> keys() const;

    double number(std::string_view key);
    std::optional<double> optional_number(std::string_view key);
    double number_or(std::string_view key, double fallback);
    std::string text(std::string_view key);
    std::optional<std::string> optional_text(std::string_view key);
    std::vector<double> numbers(std::string_view key);  // a number or an array of numbers
    std::optional<bool> optional_flag(std::string_view key);
    // Numbers checked against a range; the InputError names the key path and the range.
    double positive(std::string_view key);
    double non_negative(std::string_view key);
    std::optional<double> optional_positive(std::string_view key);
    std::optional<double> optional_non_negative(std::string_view key);
    // A whole number in [minimum, maximum] (e.g. a mode or fret count).
    std::size_t count(std::string_view key, std::size_t minimum, std::size_t maximum);
    std::optional<std::size_t> optional_count(std::string_view key, std::size_t minimum, std::size_t maximum);
    // An array of [a, b] number pairs (e.g. a curve given point by point).
    std::vector<std::array<double, 2>> number_pairs(std::string_view key);
    // A table of numbers keyed by whole numbers in [minimum, maximum], e.g. per-fret values
    // { 12 = 0.05e-3 }; empty when absent. Messages name the entry: key.12.
    std::map<std::size_t, double> numbered_numbers(std::string_view key, std::size_t minimum, std::size_t maximum);
    TomlSection section(std::string_view key);
    std::optional<TomlSection> optional_section(std::string_view key);
    // Arrays of tables ([[obstacle.points]] etc.).
    std::vector<TomlSection> sections(std::string_view key);
    // The raw node, for values with several accepted forms (e.g. a number or "native").
    const toml::node* node(std::string_view key);

    // Throws InputError naming the first key that was never read, and the key it likely
    // misspells among those looked up.
    void finish() const;
    // For a reader that failed part-way (a required key missing): throws InputError naming a
    // key of the table that was never looked up and is likely a misspelling of one that was
    // looked up and is absent ("acton12" for "action12"); nothing when there is none.
    void refuse_misspelt_keys() const;

private:
    std::optional<std::string> nearest_asked(std::string_view key, bool absent_only) const;
    void log_lookup(std::string_view key) const;
    const toml::node& required(std::string_view key);
    double to_number(const toml::node& node, std::string_view key) const;

    const toml::table* table_;
    std::string path_;
    std::set<std::string, std::less<>> used_;
    mutable std::set<std::string, std::less<>> asked_;  // every key looked up, present or not
};

}  // namespace fretbuzz
