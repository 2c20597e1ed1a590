#include "fretbuzz/input/StringsCaseFile.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include <charconv>
#include <sstream>

#include "CaseDocument.hpp"
#include "CaseReference.hpp"
#include "TomlSection.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/BuiltinFiles.hpp"
#include "fretbuzz/input/TextFile.hpp"

namespace fretbuzz {

namespace {

constexpr std::string_view kFolder = "bridges/";
constexpr std::string_view kStringsSuffix = ".toml";

// A string at rest: its modes start from zero whatever its case plucks (a sympathetic string).
void put_at_rest(Case& c) {
    c.initial_displacement.assign(c.mode_count(), 0.0);
    c.initial_velocity.assign(c.mode_count(), 0.0);
}

// Tuned by its tension: T r^2, every mode's frequency times r (exact for an ideal string; the
// stiffness's share of the partials stays as the case has it). Its damping stays.
void retune(Case& c, double r) {
    if (r == 1.0) return;
    c.string.tension_n *= r * r;
    for (double& f : c.modes.frequency_hz) f *= r;
}


// A value of `set` as TOML text, its numbers in their shortest exact form (86.74, not
// 86.739999999999995).
void append_value(std::string& out, const toml::node& node) {
    if (const auto* number = node.as_floating_point()) {
        char digits[32];
        const auto end = std::to_chars(digits, digits + sizeof digits, number->get()).ptr;
        out.append(digits, end);
    } else if (const toml::table* table = node.as_table()) {
        out += "{";
        for (const auto& [key, value] : *table) {
            out += (out.back() == '{' ? " " : ", ") + std::string(key.str()) + " = ";
            append_value(out, value);
        }
        out += " }";
    } else if (const toml::array* array = node.as_array()) {
        out += "[";
        for (std::size_t k = 0; k < array->size(); ++k) {
            if (k > 0) out += ", ";
            append_value(out, *array->get(k));
        }
        out += "]";
    } else {
        std::ostringstream text;
        node.visit([&text](const auto& v) { text << v; });
        out += text.str();
    }
}

struct Override {
    toml::source_position at;  // where it was written: overrides are listed in that order
    std::string key;           // "string.T", "gesture" (an array replaces the base's whole)
    std::string value;         // as TOML text
};

// Every key path that `set` gives, with its value.
void list_overrides(const toml::table& set, const std::string& prefix, std::vector<Override>& out) {
    for (const auto& [key, value] : set) {
        const std::string path = prefix + std::string(key.str());
        if (const toml::table* t = value.as_table()) {
            list_overrides(*t, path + ".", out);
        } else {
            std::string text;
            append_value(text, value);
            out.push_back({value.source().begin, path, text});
        }
    }
}

// The base case's document with `set` laid over it: tables merge key by key, every other
// value (a number, a text, an array, an array of tables) replaces the base's.
void lay_over(toml::table& base, const toml::table& set) {
    for (const auto& [key, value] : set) {
        toml::table* below = base[key].as_table();
        if (const toml::table* t = value.as_table(); t != nullptr && below != nullptr)
            lay_over(*below, *t);
        else
            base.insert_or_assign(key, value);
    }
}

// A message about the laid-over case, its keys named where the user wrote them: a key of
// `set` as string[i].set.KEY (and the key it likely misspells beside it), any other as the
// base case's, after the string's case key.
std::string where_in_string(std::string message, const TomlSection& s, const std::string& case_file,
                            const std::vector<Override>& overrides) {
    const auto key_at = [&message](std::size_t at, const std::string& key) {
        const std::size_t end = at + key.size();
        return message.compare(at, key.size(), key) == 0 && (at == 0 || message[at - 1] == ' ') &&
               (end == message.size() || std::string_view(" :.[=").find(message[end]) != std::string_view::npos);
    };
    const std::string set = s.key_path("set") + ".";
    for (const Override& o : overrides) {
        for (std::size_t at = 0; at < message.size(); ++at) {
            if (!key_at(at, o.key)) continue;
            message.insert(at, set);
            const std::string meant = "did you mean ";
            if (const std::size_t m = message.find(meant); m != std::string::npos) message.insert(m + meant.size(), set);
            return message;
        }
    }
    return s.key_path("case") + " = \"" + case_file + "\": " + message;
}

// The one-string case a [[string]] names, with its `set` laid over it.
Case read_string_case(const TomlSection& s, StringsCase::StringOrigin& origin, const toml::table* set,
                      const CaseText& source) {
    const std::string& file = origin.case_file;
    // A built-in case's name, or a one-string case file in this one's folder (CaseReference.hpp).
    const std::string text = read_case_reference(file, s.key_path("case"), source.data);
    if (set == nullptr) return parse_case(text, file, source.data);
    // Every string steps at the strings case's rate for its run length: a string's own would be lost.
    for (const char* key : {"fs", "duration"})
        if (set->at_path(std::string("run.") + key))
            throw InputError(s.key_path("set") + ".run." + key + ": every string runs by the strings case's [run] " + key +
                             "; set it there");
    std::vector<Override> overrides;
    list_overrides(*set, "", overrides);
    std::stable_sort(overrides.begin(), overrides.end(), [](const Override& a, const Override& b) {
        return a.at.line != b.at.line ? a.at.line < b.at.line : a.at.column < b.at.column;
    });
    for (const Override& o : overrides) origin.overrides.push_back(o.key + " = " + o.value);
    toml::table root = parse_toml_document(text, file);
    lay_over(root, *set);
    try {
        return parse_case_document(root, toml_text(root), source.data);
    } catch (const InputError& e) {
        throw InputError(where_in_string(e.what(), s, file, overrides));
    }
}

}  // namespace

std::vector<BuiltinCaseInfo> builtin_strings_cases() {
    std::vector<BuiltinCaseInfo> cases;
    for (const EmbeddedFile& f : builtin_files()) {
        const std::string_view name = f.name;
        if (!name.starts_with(kFolder) || !name.ends_with(kStringsSuffix)) continue;
        const toml::table root = parse_toml_document(f.text(), std::string(name));
        if (!root.contains("bridge")) continue;
        cases.push_back({std::string(name.substr(kFolder.size(), name.size() - kFolder.size() - kStringsSuffix.size())),
                         root["description"].value_or(std::string())});
    }
    return cases;
}

std::optional<CaseText> read_strings_case_text(const std::string& name_or_path) {
    const std::string builtin = std::string(kFolder) + name_or_path + std::string(kStringsSuffix);
    if (auto text = find_builtin_file(builtin))
        return CaseText{std::string(*text), builtin, DataSource::builtin()};
    const std::filesystem::path path(name_or_path);
    std::error_code ec;
    if (path.extension() != kStringsSuffix || !std::filesystem::is_regular_file(path, ec)) return std::nullopt;
    std::string text = read_text_file(path, "case file " + path.string(), kMaxCaseFileBytes);
    if (!parse_toml_document(text, path.string()).contains("bridge")) return std::nullopt;
    return CaseText{std::move(text), path.string(), DataSource::directory(path.parent_path())};
}

StringsCase parse_strings_case(const CaseText& source) {
    const toml::table root = parse_toml_document(source.text, source.source_name);
    TomlSection top(root, "");
    StringsCase sc;
    sc.name = top.text("name");
    sc.description = top.optional_text("description").value_or("");
    sc.source_text = source.text;
    TomlSection run = top.section("run");
    sc.run.sample_rate_hz = run.positive("fs");
    sc.run.duration_s = run.positive("duration");
    if (auto rate = run.optional_positive("output_rate")) sc.run.output_rate_hz = *rate;
    sc.run.audio_rate_hz = run.optional_positive("audio_rate").value_or(sc.run.audio_rate_hz);
    const bool lossless = run.optional_flag("lossless").value_or(false);
    run.finish();

    if (!top.has("string")) throw InputError("string: a case with a bridge needs at least one [[string]]");
    std::vector<TomlSection> strings = top.sections("string");
    if (strings.size() > StringsCase::kMaxStrings)
        throw InputError("string: " + std::to_string(strings.size()) + " strings; at most " +
                         std::to_string(StringsCase::kMaxStrings) + " rest on one bridge");
    for (TomlSection& s : strings) {
        const std::string name = s.text("name");
        // Names a CSV column and a file: letters, digits, '-' and '_', each once.
        const bool plain = !name.empty() && name.size() <= 64 && std::all_of(name.begin(), name.end(), [](char ch) {
            return std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '_';
        });
        if (!plain || name == "t" || name == "bridge" || name == "balance")
            throw InputError(s.key_path("name") + " = \"" + name +
                             "\": must be 1 to 64 letters, digits, '-' or '_' (not t, bridge or balance)");
        if (std::find(sc.string_names.begin(), sc.string_names.end(), name) != sc.string_names.end())
            throw InputError(s.key_path("name") + " = \"" + name + "\": two strings have that name");
        StringsCase::StringOrigin origin;
        origin.case_file = s.text("case");
        origin.turned = s.optional_flag("mirror").value_or(false);
        origin.at_rest = s.optional_flag("at_rest").value_or(false);
        origin.pitch_ratio = s.optional_positive("pitch_ratio").value_or(1.0);
        if (origin.pitch_ratio < 0.25 || origin.pitch_ratio > 4.0)
            throw InputError(out_of_range_message(s.key_path("pitch_ratio"), origin.pitch_ratio, "must be in [0.25, 4]"));
        const toml::node* set = s.node("set");
        if (set != nullptr && set->as_table() == nullptr)
            throw InputError(s.key_path("set") + ": must be a table of the case's keys (e.g. set.string.T = 80.0)");
        s.finish();
        Case c = read_string_case(s, origin, set != nullptr ? set->as_table() : nullptr, source);
        c.run.sample_rate_hz = sc.run.sample_rate_hz;
        c.run.duration_s = sc.run.duration_s;
        if (lossless) c.make_lossless();
        if (origin.turned) c.turn_end_for_end();
        if (origin.at_rest) put_at_rest(c);
        retune(c, origin.pitch_ratio);
        sc.string_names.push_back(name);
        sc.strings.push_back(std::move(c));
        sc.origins.push_back(std::move(origin));
    }

    TomlSection bridge = top.section("bridge");
    if (!bridge.has("mode")) throw InputError("bridge.mode: a bridge needs at least one [[bridge.mode]]");
    for (TomlSection& m : bridge.sections("mode")) {
        BridgeModeSpec spec;
        spec.mass_kg = m.number("mass_kg");
        require_positive(m.key_path("mass_kg"), spec.mass_kg);
        spec.frequency_hz = m.positive("frequency_hz");
        spec.damping_ratio = m.optional_non_negative("damping_ratio").value_or(0.0);
        if (lossless) spec.damping_ratio = 0.0;
        spec.participation = m.numbers("participation");
        m.finish();
        sc.bridge.push_back(std::move(spec));
    }
    bridge.finish();
    top.finish();
    sc.validate();
    return sc;
}

std::string describe_strings_case(const StringsCase& sc) {
    std::ostringstream text;
    text.precision(6);
    text << "\n# As fretbuzz reads it (fretbuzz show): a bridge of " << sc.bridge.size() << " mode"
         << (sc.bridge.size() == 1 ? "" : "s") << ", " << sc.strings.size() << " strings\n";
    for (std::size_t b = 0; b < sc.bridge.size(); ++b) {
        const BridgeModeSpec& m = sc.bridge[b];
        text << "#   bridge.mode[" << b << "]: M = " << m.mass_kg << " kg, f = " << m.frequency_hz
             << " Hz, damping ratio " << m.damping_ratio << ", participation";
        for (std::size_t s = 0; s < m.participation.size(); ++s)
            text << (s == 0 ? " " : ", ") << sc.string_names[s] << " " << m.participation[s];
        text << "\n";
    }
    for (std::size_t s = 0; s < sc.strings.size(); ++s) {
        const Case& c = sc.strings[s];
        const StringsCase::StringOrigin& o = sc.origins[s];
        text << "#   string[" << s << "] " << sc.string_names[s] << ": " << o.case_file;
        if (o.turned) text << " turned end for end";
        for (std::size_t k = 0; k < o.overrides.size(); ++k) text << (k == 0 ? " with " : ", ") << o.overrides[k];
        if (o.pitch_ratio != 1.0) text << "; retuned by " << o.pitch_ratio;
        text << "; f1 = " << c.modes.frequency_hz.front() << " Hz open";
        for (const FingerSpec& f : c.fingers) text << ", a finger at x = " << f.position_m << " m";
        text << (o.at_rest ? "; at rest" : "") << "\n";
    }
    return text.str();
}

}  // namespace fretbuzz
