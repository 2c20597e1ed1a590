#include "fretbuzz/setup/MapFiles.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/TextFile.hpp"

namespace fretbuzz {

namespace {

constexpr std::uintmax_t kMaxMapBytes = 64u << 20;
const std::vector<std::string> kColumns = {
    "string",      "fret",          "strength",          "verdict",   "buzz_fraction",    "buzz_fraction_low",
    "buzz_fraction_high", "buzz_dB", "buzz_fret",        "touch_fraction", "plucks",      "clean_up_to",
    "clean_up_to_value", "unit",    "stiffness_sensitive", "status",  "clearance_mm",     "audio",
    "pluck_dB",    "first_touch_s", "pluck_touch_s"};

// clean < marginal < buzzes: how a change of verdict reads.
int verdict_rank(const std::string& verdict) {
    if (verdict == "clean") return 0;
    if (verdict == "marginal") return 1;
    return verdict == "buzzes" ? 2 : -1;
}

std::string fret_text(int fret) {
    if (fret == kNoFret) return "";
    return fret == kBoard ? "board" : std::to_string(fret);
}

// A CSV cell: quoted when it holds a comma, a quote or a line break.
std::string cell(const std::string& text) {
    if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
    std::string quoted = "\"";
    for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' || c == '\r' ? ' ' : c);
    return quoted + "\"";
}

std::vector<std::string> split_row(const std::string& line) {
    std::vector<std::string> cells(1);
    bool quoted = false;
    for (std::size_t i = 0; i < line.size(); ++i) {
        const char c = line[i];
        if (quoted) {
            if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
                cells.back() += '"';
                ++i;
            } else if (c == '"') {
                quoted = false;
            } else {
                cells.back() += c;
            }
        } else if (c == '"') {
            quoted = true;
        } else if (c == ',') {
            cells.emplace_back();
        } else if (c != '\r') {
            cells.back() += c;
        }
    }
    return cells;
}

double number_of(const std::string& text) {
    if (text.empty()) return NoteVerdict::nan;
    double v = 0.0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (error != std::errc() || end != text.data() + text.size()) throw std::invalid_argument(text);
    return v;
}

int fret_of(const std::string& text) {
    if (text.empty()) return kNoFret;
    if (text == "board") return kBoard;
    const double v = number_of(text);
    if (!(v >= 1 && v <= 100 && v == std::floor(v))) throw std::invalid_argument(text);
    return static_cast<int>(v);
}

}  // namespace

std::string shortest_text(double value) {
    if (std::isnan(value)) return "";
    char buffer[32];
    const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value);
    return error == std::errc() ? std::string(buffer, end) : std::string();
}

void write_buzz_map_csv(const std::filesystem::path& path, std::span<const NoteVerdict> notes) {
    std::ofstream out(path, std::ios::binary);
    for (std::size_t c = 0; c < kColumns.size(); ++c) out << (c ? "," : "") << kColumns[c];
    out << "\n";
    for (const NoteVerdict& v : notes) {
        const auto listed = [](const std::vector<double>& values) {
            std::string text;
            for (std::size_t k = 0; k < values.size(); ++k) {
                if (k > 0) text += ';';
                text += shortest_text(values[k]);
            }
            return text;
        };
        out << cell(v.string_name) << "," << v.fret << "," << cell(v.strength) << "," << v.verdict << ","
            << shortest_text(v.buzz_fraction) << "," << shortest_text(v.buzz_fraction_low) << ","
            << shortest_text(v.buzz_fraction_high) << "," << shortest_text(v.buzz_db) << "," << fret_text(v.buzz_fret)
            << "," << shortest_text(v.touch_fraction) << "," << v.plucks << "," << shortest_text(v.clean_up_to) << ","
            << shortest_text(v.clean_up_to_value) << "," << v.unit << "," << cell(v.stiffness_sensitive) << ","
            << cell(v.status) << "," << shortest_text(v.clearance_m * 1e3) << "," << cell(v.audio) << ","
            << listed(v.pluck_db) << "," << shortest_text(v.first_touch_s) << "," << listed(v.pluck_touch_s) << "\n";
    }
    out.close();
    if (!out) throw std::runtime_error("cannot write " + path.string());
}

std::vector<NoteVerdict> read_buzz_map_csv(const std::filesystem::path& path, const std::string& option) {
    const std::string where = option + " " + path.parent_path().string();
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
        throw InputError(where + ": holds no buzz_map.csv (give the --out folder of an earlier `fretbuzz setup`)");
    const std::string text = read_text_file(path, where + ": buzz_map.csv", kMaxMapBytes);
    std::istringstream lines(text);
    std::string line;
    std::getline(lines, line);
    if (split_row(line) != kColumns)
        throw InputError(where + ": buzz_map.csv is not a map of this fretbuzz (its columns differ: run the earlier "
                                 "map again)");
    std::vector<NoteVerdict> notes;
    std::size_t row = 1;
    while (std::getline(lines, line)) {
        ++row;
        if (line.empty()) continue;
        const std::vector<std::string> c = split_row(line);
        try {
            if (c.size() != kColumns.size()) throw std::invalid_argument("columns");
            NoteVerdict v;
            v.string_name = c[0];
            const double fret = number_of(c[1]);
            if (!(fret >= 0 && fret <= 100 && fret == std::floor(fret))) throw std::invalid_argument(c[1]);
            v.fret = static_cast<std::size_t>(fret);
            v.strength = c[2];
            v.verdict = c[3];
            if (!v.verdict.empty() && verdict_rank(v.verdict) < 0) throw std::invalid_argument(c[3]);
            v.buzz_fraction = number_of(c[4]);
            v.buzz_fraction_low = number_of(c[5]);
            v.buzz_fraction_high = number_of(c[6]);
            v.buzz_db = number_of(c[7]);
            v.buzz_fret = fret_of(c[8]);
            v.touch_fraction = number_of(c[9]);
            v.plucks = static_cast<std::size_t>(std::max(0.0, number_of(c[10])));
            v.clean_up_to = number_of(c[11]);
            v.clean_up_to_value = number_of(c[12]);
            v.unit = c[13];
            v.stiffness_sensitive = c[14];
            v.status = c[15];
            v.clearance_m = number_of(c[16]) * 1e-3;
            v.audio = c[17];
            v.first_touch_s = number_of(c[19]);
            notes.push_back(std::move(v));
        } catch (const std::invalid_argument&) {
            throw InputError(where + ": buzz_map.csv line " + std::to_string(row) + " is not a row of a buzz map");
        }
    }
    return notes;
}

std::vector<NoteChange> compare_maps(std::span<const NoteVerdict> now, std::span<const NoteVerdict> before) {
    std::map<std::tuple<std::string, std::size_t, std::string>, const NoteVerdict*> earlier;
    for (const NoteVerdict& v : before) earlier[{v.string_name, v.fret, v.strength}] = &v;
    std::vector<NoteChange> changes;
    for (const NoteVerdict& v : now) {
        NoteChange c{v, {}, "new", ""};
        const auto found = earlier.find({v.string_name, v.fret, v.strength});
        if (found != earlier.end()) {
            c.before = *found->second;
            const int rank = verdict_rank(v.verdict) - verdict_rank(c.before.verdict);
            const double df = v.buzz_fraction - c.before.buzz_fraction;
            const double a = std::isnan(v.buzz_db) ? -1e9 : v.buzz_db;
            const double b = std::isnan(c.before.buzz_db) ? -1e9 : c.before.buzz_db;
            const double up_to = v.clean_up_to / c.before.clean_up_to;  // NaN or inf/inf: no change read from it
            const auto decided = [&](bool worse, const char* reason) {
                c.change = worse ? "worse" : "better";
                c.reason = reason;
            };
            if (rank != 0)
                decided(rank > 0, "verdict");
            else if (std::abs(df) > 1e-9)
                decided(df > 0, "plucks");
            else if (std::isfinite(up_to) && std::abs(std::log(up_to)) > std::log(kChangeCleanUpTo))
                decided(up_to < 1.0, "margin");
            else if (v.buzz_fraction > 0 && std::abs(a - b) >= kChangeDb)
                decided(a > b, "loudness");
            else if (v.buzz_fraction > 0 && v.buzz_fret != c.before.buzz_fret) {
                c.change = "moved";
                c.reason = "fret";
            } else
                c.change = "same";
        }
        changes.push_back(std::move(c));
    }
    return changes;
}

void write_comparison_csv(const std::filesystem::path& path, std::span<const NoteChange> changes) {
    std::ofstream out(path, std::ios::binary);
    out << "string,fret,strength,change,verdict_before,verdict,buzz_fraction_before,buzz_fraction,buzz_dB_before,"
           "buzz_dB,buzz_fret_before,buzz_fret,clean_up_to_before,clean_up_to,reason\n";
    for (const NoteChange& c : changes)
        out << cell(c.now.string_name) << "," << c.now.fret << "," << cell(c.now.strength) << "," << c.change << ","
            << c.before.verdict << "," << c.now.verdict << ","
            << (c.change == "new" ? "" : shortest_text(c.before.buzz_fraction)) << "," << shortest_text(c.now.buzz_fraction)
            << "," << shortest_text(c.before.buzz_db) << "," << shortest_text(c.now.buzz_db) << ","
            << fret_text(c.before.buzz_fret) << "," << fret_text(c.now.buzz_fret) << ","
            << shortest_text(c.before.clean_up_to) << "," << shortest_text(c.now.clean_up_to) << "," << c.reason << "\n";
    out.close();
    if (!out) throw std::runtime_error("cannot write " + path.string());
}

}  // namespace fretbuzz
