#include "TomlSection.hpp"

#include <algorithm>
#include <charconv>
#include <cctype>
#include <cmath>
#include <sstream>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/TextFile.hpp"

namespace fretbuzz {

namespace {

constexpr std::size_t kMaxKeyParts = 64;   // a.b.c: three parts; case files use at most three
constexpr std::size_t kMaxNesting = 64;    // arrays and inline tables inside each other

// The TOML parser recurses on dotted keys and nested values; a hostile file (a header of
// 50 000 parts) would overflow the stack. A linear scan refuses such files first.
void check_toml_shape(std::string_view text, const std::string& source) {
    if (text.size() > kMaxCaseFileBytes)
        throw InputError(source + ": the file is larger than " + std::to_string(kMaxCaseFileBytes >> 20) + " MiB");
    std::size_t line = 1, parts = 1;
    bool in_key = true;       // where a key may be: line start, a header, after '{' or ',' in an inline table
    bool in_header = false;
    std::string nesting;      // open '[' and '{' of values
    auto fail = [&](const std::string& what) { throw InputError(source + ":" + std::to_string(line) + ": " + what); };
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char ch = text[i];
        if (ch == '\n') {
            ++line;
            if (nesting.empty()) {
                in_key = true;
                parts = 1;
                in_header = false;
            }
        } else if (ch == '#') {
            while (i + 1 < text.size() && text[i + 1] != '\n') ++i;
        } else if (ch == '"' || ch == '\'') {
            const bool triple = text.substr(i, 3) == std::string(3, ch);
            const std::string_view end = triple ? text.substr(i, 3) : text.substr(i, 1);
            for (i += end.size(); i < text.size() && text.substr(i, end.size()) != end; ++i) {
                if (ch == '"' && text[i] == '\\') ++i;  // an escape in a basic string
                else if (text[i] == '\n') ++line;
            }
            i += end.size() - 1;
        } else if (in_key && ch == '.') {
            if (++parts > kMaxKeyParts)
                fail("a dotted key has more than " + std::to_string(kMaxKeyParts) + " parts");
        } else if (in_header) {
            if (ch == ']') in_key = false;
        } else if (in_key && nesting.empty() && ch == '[') {
            in_header = true;
            while (i + 1 < text.size() && text[i + 1] == '[') ++i;
        } else if (ch == '=') {
            in_key = false;
        } else if (ch == '[' || ch == '{') {
            nesting.push_back(ch);
            if (nesting.size() > kMaxNesting)
                fail("values are nested more than " + std::to_string(kMaxNesting) + " deep");
            if (ch == '{') {
                in_key = true;
                parts = 1;
            }
        } else if (ch == ']' || ch == '}') {
            if (!nesting.empty()) nesting.pop_back();
            in_key = false;
        } else if (ch == ',' && !nesting.empty() && nesting.back() == '{') {
            in_key = true;
            parts = 1;
        }
    }
}

}  // namespace

namespace {
// A line whose value is a number followed by a unit or a fraction, unquoted (action = 5/64"):
// the syntax error it causes is a unit's, and the message says how a value with a unit is written.
std::string unquoted_unit_hint(std::string_view text, std::size_t line) {
    std::size_t start = 0;
    for (std::size_t l = 1; l < line && start != std::string_view::npos; ++l) {
        start = text.find('\n', start);
        if (start != std::string_view::npos) ++start;
    }
    if (start == std::string_view::npos) return {};
    const std::string_view row = text.substr(start, text.find('\n', start) - start);
    const std::size_t eq = row.find('=');
    if (eq == std::string_view::npos) return {};
    const std::string_view value = trim_blanks(row.substr(eq + 1, row.find('#', eq) - eq - 1));
    if (value.empty() || !(std::isdigit(static_cast<unsigned char>(value.front())) || value.front() == '.')) return {};
    if (value.find_first_of("/\"abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ") == std::string_view::npos)
        return {};
    return "; a value with a unit is a quoted string, e.g. action = \"5/64 in\" (lengths are written \"2.4 mm\", "
           "\"0.094 in\", \"5/64 in\", \"4.5/64 in\", \"1 3/16 in\" or '5/64\"')";
}
}  // namespace

toml::table parse_toml_document(std::string_view text, const std::string& source) {
    check_toml_shape(text, source);
    try {
        return toml::parse(text, source);
    } catch (const toml::parse_error& e) {
        std::ostringstream msg;
        msg << source << ":" << e.source().begin.line << ":" << e.source().begin.column << ": " << e.description()
            << unquoted_unit_hint(text, e.source().begin.line);
        throw InputError(msg.str());
    }
}

TomlSection::TomlSection(const toml::table& table, std::string path) : table_(&table), path_(std::move(path)) {}

std::string TomlSection::key_path(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

namespace {
// Where key paths looked up are logged while case_keys_looked_up parses (one thread).
thread_local std::set<std::string>* key_log = nullptr;
}  // namespace

void TomlSection::log_lookup(std::string_view key) const {
    asked_.emplace(key);
    if (key_log == nullptr) return;
    std::string path = key_path(key);
    // obstacle[1].type and obstacle.type are the same key of the schema.
    for (std::size_t open = path.find('['); open != std::string::npos; open = path.find('['))
        path.erase(open, path.find(']', open) - open + 1);
    key_log->insert(std::move(path));
}

KeyLogScope::KeyLogScope(std::set<std::string>& log) : previous_(key_log) { key_log = &log; }
KeyLogScope::~KeyLogScope() { key_log = previous_; }

bool TomlSection::has(std::string_view key) const {
    log_lookup(key);
    return table_->contains(key);
}

std::vector<std::string> TomlSection::keys() const {
    std::vector<std::string> out;
    for (const auto& [key, value] : *table_) out.emplace_back(key.str());
    return out;
}

namespace {
// Edit distance between two short keys, to point at a likely typo.
std::size_t edit_distance(std::string_view a, std::string_view b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        std::size_t diagonal = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t next = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
            diagonal = row[j];
            row[j] = next;
        }
    }
    return row[b.size()];
}
}  // namespace

const toml::node& TomlSection::required(std::string_view key) {
    log_lookup(key);
    const toml::node* n = table_->get(key);
    if (n == nullptr) {
        std::string hint;
        for (const auto& [present, value] : *table_)
            if (!used_.contains(present.str()) && edit_distance(present.str(), key) <= 2)
                hint = "; found " + key_path(present.str()) + " instead: a typo?";
        throw InputError(key_path(key) + " is missing (required)" + hint);
    }
    used_.emplace(key);
    return *n;
}

const toml::node* TomlSection::node(std::string_view key) {
    log_lookup(key);
    const toml::node* n = table_->get(key);
    if (n != nullptr) used_.emplace(key);
    return n;
}

double TomlSection::to_number(const toml::node& n, std::string_view key) const {
    double value = 0.0;
    if (const auto* f = n.as_floating_point())
        value = f->get();
    else if (const auto* i = n.as_integer())
        value = static_cast<double>(i->get());
    else
        throw InputError(key_path(key) + " must be a number");
    if (!std::isfinite(value)) throw InputError(key_path(key) + " = " + std::to_string(value) + " must be finite");
    return value;
}

double TomlSection::number(std::string_view key) { return to_number(required(key), key); }

std::optional<double> TomlSection::optional_number(std::string_view key) {
    if (!has(key)) return std::nullopt;
    return number(key);
}

double TomlSection::number_or(std::string_view key, double fallback) {
    return optional_number(key).value_or(fallback);
}

std::string TomlSection::text(std::string_view key) {
    const toml::node& n = required(key);
    if (const auto* s = n.as_string()) return s->get();
    throw InputError(key_path(key) + " must be a string");
}

std::optional<std::string> TomlSection::optional_text(std::string_view key) {
    if (!has(key)) return std::nullopt;
    return text(key);
}

std::optional<bool> TomlSection::optional_flag(std::string_view key) {
    if (!has(key)) return std::nullopt;
    const toml::node& n = required(key);
    if (const auto* b = n.as_boolean()) return b->get();
    throw InputError(key_path(key) + " must be true or false");
}

std::vector<double> TomlSection::numbers(std::string_view key) {
    const toml::node& n = required(key);
    std::vector<double> values;
    if (const auto* array = n.as_array()) {
        for (std::size_t k = 0; k < array->size(); ++k)
            values.push_back(to_number(*array->get(k), std::string(key) + "[" + std::to_string(k) + "]"));
    } else {
        values.push_back(to_number(n, key));
    }
    return values;
}

double TomlSection::positive(std::string_view key) {
    const double value = number(key);
    require_positive(key_path(key), value);
    return value;
}

double TomlSection::non_negative(std::string_view key) {
    const double value = number(key);
    require_non_negative(key_path(key), value);
    return value;
}

std::optional<double> TomlSection::optional_positive(std::string_view key) {
    if (!has(key)) return std::nullopt;
    return positive(key);
}

std::optional<double> TomlSection::optional_non_negative(std::string_view key) {
    if (!has(key)) return std::nullopt;
    return non_negative(key);
}

std::size_t TomlSection::count(std::string_view key, std::size_t minimum, std::size_t maximum) {
    const double value = number(key);
    const bool whole = value == std::floor(value);
    if (!whole || value < static_cast<double>(minimum) || value > static_cast<double>(maximum))
        throw InputError(out_of_range_message(key_path(key), value,
                                              "must be a whole number in [" + std::to_string(minimum) + ", " +
                                                  std::to_string(maximum) + "]"));
    return static_cast<std::size_t>(value);
}

std::optional<std::size_t> TomlSection::optional_count(std::string_view key, std::size_t minimum,
                                                       std::size_t maximum) {
    if (!has(key)) return std::nullopt;
    return count(key, minimum, maximum);
}

std::vector<std::array<double, 2>> TomlSection::number_pairs(std::string_view key) {
    const toml::node& n = required(key);
    const auto* array = n.as_array();
    const std::string expected = " must be an array of [a, b] number pairs, e.g. [[0.1, 2e-4], [0.3, 5e-4]]";
    if (array == nullptr) throw InputError(key_path(key) + expected);
    std::vector<std::array<double, 2>> pairs;
    for (std::size_t k = 0; k < array->size(); ++k) {
        const std::string item = std::string(key) + "[" + std::to_string(k) + "]";
        const auto* pair = array->get(k)->as_array();
        if (pair == nullptr || pair->size() != 2) throw InputError(key_path(item) + expected);
        pairs.push_back({to_number(*pair->get(0), item + "[0]"), to_number(*pair->get(1), item + "[1]")});
    }
    return pairs;
}

std::map<std::size_t, double> TomlSection::numbered_numbers(std::string_view key, std::size_t minimum,
                                                            std::size_t maximum) {
    std::map<std::size_t, double> values;
    if (!has(key)) return values;
    const toml::node& n = required(key);
    const auto* table = n.as_table();
    if (table == nullptr)
        throw InputError(key_path(key) + " must be a table of numbers by number, e.g. { " + std::to_string(minimum) +
                         " = 0.05e-3 }");
    for (const auto& [name, value] : *table) {
        const std::string entry = std::string(key) + "." + std::string(name.str());
        std::size_t number = 0;
        const auto [end, error] = std::from_chars(name.str().data(), name.str().data() + name.str().size(), number);
        if (error != std::errc() || end != name.str().data() + name.str().size() || number < minimum ||
            number > maximum)
            throw InputError(key_path(entry) + ": \"" + std::string(name.str()) + "\" must be a whole number in [" +
                             std::to_string(minimum) + ", " + std::to_string(maximum) + "]");
        values[number] = to_number(value, entry);
    }
    return values;
}

TomlSection TomlSection::section(std::string_view key) {
    const toml::node& n = required(key);
    if (const auto* t = n.as_table()) return TomlSection(*t, key_path(key));
    throw InputError(key_path(key) + " must be a table ([" + key_path(key) + "])");
}

std::optional<TomlSection> TomlSection::optional_section(std::string_view key) {
    if (!has(key)) return std::nullopt;
    return section(key);
}

std::vector<TomlSection> TomlSection::sections(std::string_view key) {
    const toml::node& n = required(key);
    std::vector<TomlSection> result;
    if (const auto* t = n.as_table()) {
        result.emplace_back(*t, key_path(key));
        return result;
    }
    const auto* array = n.as_array();
    if (array == nullptr) throw InputError(key_path(key) + " must be a table or an array of tables");
    for (std::size_t k = 0; k < array->size(); ++k) {
        const auto* t = array->get(k)->as_table();
        if (t == nullptr) throw InputError(key_path(key) + "[" + std::to_string(k) + "] must be a table");
        result.emplace_back(*t, key_path(key) + "[" + std::to_string(k) + "]");
    }
    return result;
}

namespace {
// Two keys close enough that one is likely a typo of the other: one edit apart, or two
// when both are long (so that "nut" is not taken for "mu").
bool close_keys(std::string_view a, std::string_view b) {
    const std::size_t d = edit_distance(a, b);
    return d <= 1 || (d == 2 && std::min(a.size(), b.size()) >= 6);
}
}  // namespace

std::optional<std::string> TomlSection::nearest_asked(std::string_view key, bool absent_only) const {
    std::optional<std::string> best;
    std::size_t best_distance = 0;
    for (const std::string& asked : asked_) {
        if (asked == key || (absent_only && table_->contains(asked)) || !close_keys(key, asked)) continue;
        const std::size_t d = edit_distance(key, asked);
        if (!best || d < best_distance) {
            best = asked;
            best_distance = d;
        }
    }
    return best;
}

void TomlSection::refuse_misspelt_keys() const {
    for (const auto& [key, value] : *table_) {
        if (asked_.contains(key.str())) continue;
        if (const auto meant = nearest_asked(key.str(), true))
            throw InputError("unknown key " + key_path(key.str()) + ": did you mean " + key_path(*meant) +
                             "? (see `fretbuzz show` for the keys)");
    }
}

void TomlSection::finish() const {
    for (const auto& [key, value] : *table_) {
        if (used_.contains(key.str())) continue;
        const auto meant = nearest_asked(key.str(), false);
        throw InputError("unknown key " + key_path(key.str()) +
                         (meant ? ": did you mean " + key_path(*meant) + "?" : " (check its spelling)") +
                         " (see `fretbuzz show` for the keys)");
    }
}

}  // namespace fretbuzz
