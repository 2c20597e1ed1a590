// Sweep specs: reading them, counting and expanding their runs, and building each run's
// case by setting its values in the base case's parsed document.
#include "fretbuzz/input/SweepSpec.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <sstream>

#include "CaseDocument.hpp"
#include "TomlSection.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/TextFile.hpp"

namespace fretbuzz {

// The base case's document and the swept values as parsed TOML nodes (each list a TOML
// array, so a value keeps its type: a number, a string, an array, a table).
class SweepDocument {
public:
    struct List {
        std::string key;
        bool label = false;
        toml::array values;
        std::vector<std::string> texts;  // as in the table
    };
    toml::table base;
    std::vector<std::string> fixed_keys;
    toml::array fixed_values;
    std::vector<List> lists;
    bool zip = false;
};

namespace {

// A value as the table shows it.
std::string table_text(const toml::node& node, const std::string& where) {
    if (const auto* f = node.as_floating_point()) {
        if (!std::isfinite(f->get())) throw InputError(where + " must be finite");
        return sweep_number_text(f->get());
    }
    if (const auto* i = node.as_integer()) return std::to_string(i->get());
    if (const auto* s = node.as_string()) return s->get();
    if (const auto* b = node.as_boolean()) return b->get() ? "true" : "false";
    std::ostringstream toml;
    if (const auto* a = node.as_array()) {
        toml << *a;
    } else if (const auto* t = node.as_table()) {
        // A whole table as one value (e.g. obstacle.frets.height_offsets = { 3 = 1e-4 }).
        toml::table inline_table = *t;
        inline_table.is_inline(true);
        toml << inline_table;
    } else {
        throw InputError(where + " must be a number, a string, true/false, an array or a table");
    }
    return toml.str();
}

// [[parameter]]: key, and values or from/to/count/scale.
SweepDocument::List read_parameter(TomlSection s) {
    SweepDocument::List list;
    list.key = s.text("key");
    list.label = s.optional_flag("label").value_or(false);
    const std::string& key = list.key;
    if (key.empty()) throw InputError(s.key_path("key") + " is empty: give a case-file key such as \"contact.K\"");
    if (s.has("values")) {
        if (s.has("from") || s.has("to") || s.has("count"))
            throw InputError(s.path() + " (" + key + "): give either values or from/to/count, not both");
        const auto* array = s.node("values")->as_array();
        if (array == nullptr) throw InputError(s.key_path("values") + " (" + key + ") must be an array of values");
        if (array->empty())
            throw InputError(s.key_path("values") + " (" + key + ") is an empty list: give at least one value");
        for (std::size_t k = 0; k < array->size(); ++k) {
            const toml::node& node = *array->get(k);
            list.texts.push_back(table_text(node, s.key_path("values") + "[" + std::to_string(k) + "] (" + key + ")"));
            list.values.push_back(node);
        }
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
            list.texts.push_back(table_text(toml::value<double>(x), s.path() + " (" + key + ")"));
            list.values.push_back(x);
        }
    }
    s.finish();
    return list;
}

// [set] as dotted keys: both "run.duration" = 1 and run.duration = 1 (a nested table).
void flatten(const toml::table& table, const std::string& prefix, SweepSpec& spec, SweepDocument& doc) {
    for (const auto& [k, node] : table) {
        const std::string key = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
        if (const auto* t = node.as_table()) {
            flatten(*t, key, spec, doc);
            continue;
        }
        spec.fixed.push_back({key, table_text(node, "set." + key), false});
        doc.fixed_keys.push_back(key);
        doc.fixed_values.push_back(node);
    }
}

// How many runs the lists make, refused past max_runs before any run is made.
std::size_t count_runs(const std::vector<SweepDocument::List>& lists, bool zip, std::size_t max_runs,
                       const std::string& source) {
    if (lists.empty()) return 1;
    if (zip) {
        for (std::size_t a = 1; a < lists.size(); ++a)
            if (lists[a].values.size() != lists[0].values.size())
                throw InputError("parameter[" + std::to_string(a) + "] (" + lists[a].key +
                                 "): combine = \"zip\" needs lists of equal length (" +
                                 std::to_string(lists[a].values.size()) + " vs " +
                                 std::to_string(lists[0].values.size()) + ")");
    }
    std::size_t n = zip ? lists[0].values.size() : 1;
    std::string product;
    bool over = n > max_runs;
    for (std::size_t a = 0; a < lists.size(); ++a) {
        const std::size_t size = lists[a].values.size();
        product += (a == 0 ? "" : " x ") + std::to_string(size) + " (" + lists[a].key + ")";
        if (zip) continue;
        if (size != 0 && n > max_runs / size) over = true;  // also keeps the product from overflowing
        if (!over) n *= size;
    }
    if (over)
        throw InputError(source + ": the sweep has " + (zip ? std::to_string(lists[0].values.size()) : product) +
                         " runs, more than the limit of " + std::to_string(max_runs) +
                         " runs (checking and running them would take days); split it into smaller sweeps, or "
                         "raise the limit with fretbuzz sweep --max-runs N (Python: max_runs=N), up to " +
                         std::to_string(kMostSweepRuns));
    return n;
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

void assign(toml::table& root, const std::string& key, const toml::node& value) {
    const std::vector<KeyPart> parts = split_key(key);
    toml::table* table = &root;
    for (std::size_t k = 0; k + 1 < parts.size(); ++k) table = &descend(*table, parts[k], key);
    if (parts.back().index) throw InputError("parameter key \"" + key + "\": the last part cannot be indexed");
    table->insert_or_assign(parts.back().name, value);
}

// Which value of each list run `index` takes.
std::vector<std::size_t> positions(const SweepDocument& doc, std::size_t index) {
    std::vector<std::size_t> at(doc.lists.size(), index);
    if (doc.zip) return at;
    std::size_t rest = index;
    for (std::size_t a = doc.lists.size(); a-- > 0;) {
        at[a] = rest % doc.lists[a].values.size();
        rest /= doc.lists[a].values.size();
    }
    return at;
}

toml::table edited_document(const SweepSpec& spec, const SweepRun& run) {
    const SweepDocument& doc = spec.runs.document();
    toml::table root = doc.base;
    for (std::size_t k = 0; k < doc.fixed_keys.size(); ++k) assign(root, doc.fixed_keys[k], *doc.fixed_values.get(k));
    const std::vector<std::size_t> at = positions(doc, run.index);
    for (std::size_t a = 0; a < doc.lists.size(); ++a)
        if (!doc.lists[a].label) assign(root, doc.lists[a].key, *doc.lists[a].values.get(at[a]));
    return root;
}

Case read_document(const SweepSpec& spec, const SweepRun& run, const toml::table& root) {
    try {
        return parse_case_document(root, toml_text(root), spec.base.data);
    } catch (const InputError& e) {
        throw InputError(spec.source_name + ", " + describe(run) + ": " + e.what());
    }
}

}  // namespace

SweepRun SweepRuns::operator[](std::size_t index) const {
    if (index >= count_)
        throw InputError("sweep run " + std::to_string(index) + " does not exist (the sweep has " +
                         std::to_string(count_) + " runs)");
    SweepRun run{index, {}};
    const std::vector<std::size_t> at = positions(*document_, index);
    for (std::size_t a = 0; a < at.size(); ++a) {
        const SweepDocument::List& list = document_->lists[a];
        run.values.push_back({list.key, list.texts[at[a]], list.label});
    }
    return run;
}

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

std::string describe(const SweepRun& run) {
    std::string text = "run " + std::to_string(run.index);
    for (std::size_t k = 0; k < run.values.size(); ++k)
        text += (k == 0 ? " (" : ", ") + run.values[k].key + " = " + run.values[k].text;
    return text + (run.values.empty() ? "" : ")");
}

SweepSpec parse_sweep(const std::string& text, const std::string& source_name, const std::filesystem::path& base_dir,
                      std::size_t max_runs) {
    if (max_runs < 1 || max_runs > kMostSweepRuns)
        throw InputError(out_of_range_message("max_runs (the most runs a sweep may have)",
                                              static_cast<double>(max_runs),
                                              "must be in [1, " + std::to_string(kMostSweepRuns) + "]"));
    const toml::table root = parse_toml_document(text, source_name);
    TomlSection top(root, "");
    SweepSpec spec;
    spec.source_name = source_name;
    spec.text = text;
    spec.max_runs = max_runs;
    auto doc = std::make_shared<SweepDocument>();
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
        doc->zip = combine == "zip";
        s.finish();
    }
    if (top.has("parameter"))
        for (TomlSection& p : top.sections("parameter")) doc->lists.push_back(read_parameter(p));
    for (std::size_t a = 0; a < doc->lists.size(); ++a) {
        for (std::size_t b = 0; b < a; ++b)
            if (doc->lists[a].key == doc->lists[b].key)
                throw InputError("parameter[" + std::to_string(a) + "]: key \"" + doc->lists[a].key +
                                 "\" is swept twice");
        spec.parameter_keys.push_back(doc->lists[a].key);
    }
    const std::size_t count = count_runs(doc->lists, doc->zip, max_runs, source_name);
    // [set] holds case-file keys, checked when the cases are built.
    if (top.optional_section("set")) flatten(*root["set"].as_table(), "", spec, *doc);
    top.finish();
    doc->base = parse_toml_document(spec.base.text, spec.base.source_name);
    spec.runs = SweepRuns(std::move(doc), count);
    return spec;
}

SweepSpec load_sweep(const std::filesystem::path& path, std::size_t max_runs) {
    return parse_sweep(read_text_file(path, "sweep spec " + path.string(), kMaxCaseFileBytes), path.string(),
                       path.parent_path(), max_runs);
}

Case sweep_case(const SweepSpec& spec, const SweepRun& run) {
    try {
        return read_document(spec, run, edited_document(spec, run));
    } catch (const InputError& e) {
        const std::string what = e.what();
        if (what.starts_with(spec.source_name)) throw;
        throw InputError(spec.source_name + ", " + describe(run) + ": " + what);
    }
}

Case sweep_case_without_obstacle(const SweepSpec& spec, const SweepRun& run) {
    toml::table root = edited_document(spec, run);
    root.insert_or_assign("obstacle", toml::table{{"type", "none"}});
    return read_document(spec, run, root);
}

}  // namespace fretbuzz
