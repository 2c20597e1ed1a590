#include "TomlSection.hpp"

#include <cmath>

#include "fretbuzz/Error.hpp"

namespace fretbuzz {

TomlSection::TomlSection(const toml::table& table, std::string path) : table_(&table), path_(std::move(path)) {}

std::string TomlSection::key_path(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

bool TomlSection::has(std::string_view key) const { return table_->contains(key); }

const toml::node& TomlSection::required(std::string_view key) {
    const toml::node* n = table_->get(key);
    if (n == nullptr) throw InputError(key_path(key) + " is missing (required)");
    used_.emplace(key);
    return *n;
}

const toml::node* TomlSection::node(std::string_view key) {
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

void TomlSection::finish() const {
    for (const auto& [key, value] : *table_) {
        if (!used_.contains(key.str()))
            throw InputError("unknown key " + key_path(key.str()) + " (check its spelling; see `fretbuzz show` for the keys)");
    }
}

}  // namespace fretbuzz
