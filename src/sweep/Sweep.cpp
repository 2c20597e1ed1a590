// Sweep specs: reading them, expanding their parameters into runs, and building each
// run's case by writing its values into the base case file's TOML document.
#include "fretbuzz/sweep/Sweep.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>

#include "../input/TomlSection.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/analysis/BuzzMetrics.hpp"
#include "fretbuzz/input/TextFile.hpp"

namespace fretbuzz {

namespace {

// A TOML value as TOML text and as table text.
SweepValue make_value(const std::string& key, const toml::node& node, const std::string& where) {
    SweepValue v{key, "", ""};
    if (const auto* f = node.as_floating_point()) {
        if (!std::isfinite(f->get())) throw InputError(where + " must be finite");
        v.text = sweep_number_text(f->get());
    } else if (const auto* i = node.as_integer()) {
        v.text = std::to_string(i->get());
    } else if (const auto* s = node.as_string()) {
        v.text = s->get();
    } else if (const auto* b = node.as_boolean()) {
        v.text = b->get() ? "true" : "false";
    } else if (!node.is_array() && !node.is_table()) {
        throw InputError(where + " must be a number, a string, true/false, an array or a table");
    }
    std::ostringstream toml;
    if (const auto* s = node.as_string())
        toml << toml::value<std::string>(s->get());
    else if (const auto* a = node.as_array())
        toml << *a;
    else if (const auto* t = node.as_table()) {
        // A whole table as one value (e.g. obstacle.frets.height_offsets = { 3 = 1e-4 }).
        toml::table inline_table = *t;
        inline_table.is_inline(true);
        toml << inline_table;
    }    else if (const auto* f = node.as_floating_point())
        toml << *f;
    else if (const auto* i = node.as_integer())
        toml << *i;
    else if (const auto* b = node.as_boolean())
        toml << *b;
    v.toml = toml.str();
    if (v.text.empty()) v.text = v.toml;
    return v;
}

SweepValue number_value(const std::string& key, double x) {
    return make_value(key, toml::value<double>(x), key);
}

// [[parameter]]: key, and values or from/to/count/scale.
std::vector<SweepValue> read_parameter(TomlSection s) {
    const std::string key = s.text("key");
    const bool label = s.optional_flag("label").value_or(false);
    if (key.empty()) throw InputError(s.key_path("key") + " is empty: give a case-file key such as \"contact.K\"");
    std::vector<SweepValue> values;
    if (s.has("values")) {
        if (s.has("from") || s.has("to") || s.has("count"))
            throw InputError(s.path() + " (" + key + "): give either values or from/to/count, not both");
        const toml::node* node = s.node("values");
        const auto* array = node->as_array();
        if (array == nullptr) throw InputError(s.key_path("values") + " (" + key + ") must be an array of values");
        if (array->empty())
            throw InputError(s.key_path("values") + " (" + key + ") is an empty list: give at least one value");
        for (std::size_t k = 0; k < array->size(); ++k)
            values.push_back(
                make_value(key, *array->get(k), s.key_path("values") + "[" + std::to_string(k) + "] (" + key + ")"));
    } else {
        const double from = s.number("from");
        const double to = s.number("to");
        const std::size_t count = s.count("count", 1, 100000);
        const std::string scale = s.optional_text("scale").value_or("linear");
        if (scale != "linear" && scale != "log")
            throw InputError(s.key_path("scale") + " = \"" + scale + "\": must be \"linear\" or \"log\"");
        if (scale == "log" && !(from > 0.0 && to > 0.0))
            throw InputError(s.path() + " (" + key + "): a log grid needs from > 0 and to > 0");
        for (std::size_t k = 0; k < count; ++k) {
            const double r = count == 1 ? 0.0 : static_cast<double>(k) / static_cast<double>(count - 1);
            double x = scale == "log" ? from * std::pow(to / from, r) : from + r * (to - from);
            if (k + 1 == count && count > 1) x = to;  // the end points exactly as written
            if (k == 0) x = from;
            values.push_back(number_value(key, x));
        }
    }
    s.finish();
    for (SweepValue& v : values) v.label = label;
    return values;
}

// [set] as dotted keys: both "run.duration" = 1 and run.duration = 1 (a nested table).
void flatten(const toml::table& table, const std::string& prefix, std::vector<SweepValue>& out) {
    for (const auto& [k, node] : table) {
        const std::string key = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
        if (const auto* t = node.as_table())
            flatten(*t, key, out);
        else
            out.push_back(make_value(key, node, "set." + key));
    }
}

// One part of a dotted key: a name and an optional [index].
struct KeyPart {
    std::string name;
    std::optional<std::size_t> index;
};

std::vector<KeyPart> split_key(const std::string& key) {
    std::vector<KeyPart> parts;
    std::size_t start = 0;
    while (true) {
        const std::size_t dot = key.find('.', start);
        std::string part = key.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
        KeyPart p;
        if (const std::size_t open = part.find('['); open != std::string::npos) {
            const std::size_t close = part.find(']', open);
            std::size_t index = 0;
            const auto r = std::from_chars(part.data() + open + 1, part.data() + close, index);
            if (close == std::string::npos || close + 1 != part.size() || r.ec != std::errc() ||
                r.ptr != part.data() + close)
                throw InputError("parameter key \"" + key + "\": \"" + part + "\" is not name or name[index]");
            p.index = index;
            part.resize(open);
        }
        if (part.empty()) throw InputError("parameter key \"" + key + "\": an empty part");
        p.name = part;
        parts.push_back(p);
        if (dot == std::string::npos) break;
        start = dot + 1;
    }
    return parts;
}

// The table a part names, created if absent; arrays of tables need an index unless they
// hold just one.
toml::table& descend(toml::table& table, const KeyPart& part, const std::string& key) {
    toml::node* node = table.get(part.name);
    if (node == nullptr) {
        if (part.index && *part.index != 0)
            throw InputError("parameter key \"" + key + "\": the case has no " + part.name + " tables to index");
        return *table.insert_or_assign(part.name, toml::table{}).first->second.as_table();
    }
    if (auto* t = node->as_table()) {
        if (part.index && *part.index != 0)
            throw InputError("parameter key \"" + key + "\": the case has one [" + part.name + "]; use index 0 or none");
        return *t;
    }
    if (auto* a = node->as_array()) {
        if (!part.index && a->size() != 1)
            throw InputError("parameter key \"" + key + "\": the case has " + std::to_string(a->size()) + " [[" +
                             part.name + "]] tables; say which, e.g. " + part.name + "[0]");
        const std::size_t k = part.index.value_or(0);
        if (k >= a->size() || !a->get(k)->is_table())
            throw InputError("parameter key \"" + key + "\": " + part.name + "[" + std::to_string(k) +
                             "] is not one of its " + std::to_string(a->size()) + " tables");
        return *a->get(k)->as_table();
    }
    throw InputError("parameter key \"" + key + "\": " + part.name + " is a value, not a table");
}

void assign(toml::table& root, const SweepValue& v) {
    const std::vector<KeyPart> parts = split_key(v.key);
    toml::table* table = &root;
    for (std::size_t k = 0; k + 1 < parts.size(); ++k) table = &descend(*table, parts[k], v.key);
    if (parts.back().index) throw InputError("parameter key \"" + v.key + "\": the last part cannot be indexed");
    toml::table parsed = parse_toml_document("v = " + v.toml, v.key);
    table->insert_or_assign(parts.back().name, std::move(*parsed.get("v")));
}

std::string describe(const SweepRun& run) {
    std::string text = "run " + std::to_string(run.index);
    for (std::size_t k = 0; k < run.values.size(); ++k)
        text += (k == 0 ? " (" : ", ") + run.values[k].key + " = " + run.values[k].text;
    return text + (run.values.empty() ? "" : ")");
}

toml::table edited_document(const SweepSpec& spec, const SweepRun& run) {
    toml::table root = parse_toml_document(spec.base.text, spec.base.source_name);
    for (const SweepValue& v : spec.fixed) assign(root, v);
    for (const SweepValue& v : run.values)
        if (!v.label) assign(root, v);
    return root;
}

Case parse_document_case(const SweepSpec& spec, const SweepRun& run, const toml::table& root) {
    std::ostringstream text;
    text << root;
    try {
        return parse_case(text.str(), spec.base.source_name, spec.base.data);
    } catch (const InputError& e) {
        throw InputError(spec.source_name + ", " + describe(run) + ": " + e.what());
    }
}

}  // namespace

// The shortest %g form that reads back as the same double ("400000", "1e+13", "0.1").
std::string sweep_number_text(double v) {
    char buffer[64];
    if (v == std::trunc(v) && std::abs(v) < 1e7) {  // whole numbers of a usual size in full
        std::snprintf(buffer, sizeof buffer, "%.0f", v);
        return buffer;
    }
    for (int digits = 1;; ++digits) {
        std::snprintf(buffer, sizeof buffer, "%.*g", digits, v);
        if (digits >= 17 || std::strtod(buffer, nullptr) == v) return buffer;
    }
}

SweepSpec parse_sweep(const std::string& text, const std::string& source_name, const std::filesystem::path& base_dir) {
    const toml::table root = parse_toml_document(text, source_name);
    TomlSection top(root, "");
    SweepSpec spec;
    spec.source_name = source_name;
    spec.text = text;
    {
        TomlSection s = top.section("sweep");
        std::string name = s.text("case");
        const std::filesystem::path path(name);
        if (path.extension() == ".toml" && path.is_relative()) name = (base_dir / path).string();
        spec.base = read_case_text(name);
        spec.audio = s.optional_flag("audio").value_or(false);
        spec.buzz_band_hz = s.optional_positive("buzz_band").value_or(spec.buzz_band_hz);
        const std::string combine = s.optional_text("combine").value_or("grid");
        if (combine != "grid" && combine != "zip")
            throw InputError(s.key_path("combine") + " = \"" + combine + "\": must be \"grid\" or \"zip\"");
        s.finish();

        std::vector<std::vector<SweepValue>> lists;
        if (top.has("parameter"))
            for (TomlSection& p : top.sections("parameter")) lists.push_back(read_parameter(p));
        for (std::size_t a = 0; a < lists.size(); ++a) {
            for (std::size_t b = 0; b < a; ++b)
                if (lists[a][0].key == lists[b][0].key)
                    throw InputError("parameter[" + std::to_string(a) + "]: key \"" + lists[a][0].key +
                                     "\" is swept twice");
            spec.parameter_keys.push_back(lists[a][0].key);
        }
        if (combine == "zip") {
            for (std::size_t a = 1; a < lists.size(); ++a)
                if (lists[a].size() != lists[0].size())
                    throw InputError("parameter[" + std::to_string(a) + "] (" + lists[a][0].key + "): combine = \"zip\" needs lists of equal length (" +
                                     std::to_string(lists[a].size()) + " vs " + std::to_string(lists[0].size()) + ")");
            const std::size_t n = lists.empty() ? 1 : lists[0].size();
            for (std::size_t k = 0; k < n; ++k) {
                SweepRun run{k, {}};
                for (const auto& list : lists) run.values.push_back(list[k]);
                spec.runs.push_back(run);
            }
        } else {
            // Every combination; the last parameter varies fastest.
            std::size_t n = 1;
            for (const auto& list : lists) n *= list.size();
            for (std::size_t k = 0; k < n; ++k) {
                SweepRun run{k, {}};
                std::size_t rest = k;
                run.values.resize(lists.size());
                for (std::size_t a = lists.size(); a-- > 0;) {
                    run.values[a] = lists[a][rest % lists[a].size()];
                    rest /= lists[a].size();
                }
                spec.runs.push_back(run);
            }
        }
    }
    // [set] holds case-file keys, checked when the cases are built.
    if (top.optional_section("set")) flatten(*root["set"].as_table(), "", spec.fixed);
    top.finish();
    return spec;
}

SweepSpec load_sweep(const std::filesystem::path& path) {
    return parse_sweep(read_text_file(path, "sweep spec " + path.string(), kMaxCaseFileBytes), path.string(),
                       path.parent_path());
}

Case sweep_case(const SweepSpec& spec, const SweepRun& run) {
    try {
        return parse_document_case(spec, run, edited_document(spec, run));
    } catch (const InputError& e) {
        const std::string what = e.what();
        if (what.starts_with(spec.source_name)) throw;
        throw InputError(spec.source_name + ", " + describe(run) + ": " + what);
    }
}

Case obstacle_free_case(const SweepSpec& spec, const SweepRun& run) {
    toml::table root = edited_document(spec, run);
    // A fretted note keeps what stops it (the finger, the fret it presses on): its reference
    // is the same note with nothing to buzz against past the stopping fret.
    if (Case c = parse_document_case(spec, run, root); !c.fingers.empty()) {
        const std::size_t first = first_buzz_point(c);
        for (std::size_t i = first; i < c.obstacle_height_m.size(); ++i)
            c.obstacle_height_m[i] = -std::numeric_limits<double>::infinity();
        return c;
    }
    root.insert_or_assign("obstacle", toml::table{{"type", "none"}});
    return parse_document_case(spec, run, root);
}

void check_sweep(const SweepSpec& spec) {
    for (const SweepRun& run : spec.runs) {
        const Case c = sweep_case(spec, run);
        try {
            c.validate();
        } catch (const InputError& e) {
            throw InputError(spec.source_name + ", " + describe(run) + ": " + e.what());
        }
    }
}

}  // namespace fretbuzz
