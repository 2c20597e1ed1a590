#include "fretbuzz/setup/Calibration.hpp"

#include <algorithm>
#include <cctype>
#include <csignal>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "../output/JsonText.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/TextFile.hpp"
#include "fretbuzz/setup/NoteJudge.hpp"

namespace fretbuzz {

namespace {

constexpr std::size_t kMaxPlayerFileBytes = 1u << 20;  // calibration.json: about 300 bytes a note, and --player reads one number
const char* const kReportColumns = "string, fret, heard and optionally strength";

// A cell as a message quotes it: short, whatever the file holds.
std::string quoted_cell(std::string_view cell) {
    std::string text(cell.substr(0, 32));
    for (char& c : text)
        if (!std::isprint(static_cast<unsigned char>(c))) c = '?';
    return "\"" + text + (cell.size() > 32 ? "...\"" : "\"");
}

// The report's cells: comma-separated words, blanks trimmed, a pair of double quotes (as a
// spreadsheet writes them) taken off.
std::vector<std::string> report_cells(std::string_view line) {
    std::vector<std::string> cells;
    std::size_t start = 0;
    while (true) {
        const std::size_t comma = line.find(',', start);
        std::string_view cell = trim_blanks(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
        if (cell.size() >= 2 && cell.front() == '"' && cell.back() == '"') cell = trim_blanks(cell.substr(1, cell.size() - 2));
        cells.emplace_back(cell);
        if (comma == std::string_view::npos) break;
        start = comma + 1;
    }
    return cells;
}

std::string lower_case(std::string text) {
    for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return text;
}

// A buzz row's clean_up_to as the fit uses it: an unbounded one ("at least the cap") is the cap.
double searched(double clean_up_to) { return std::min(clean_up_to, kCleanUpToCap); }

// At scale s the bench hears the note buzz when s exceeds its clean_up_to (a note that is
// clean up to at least the cap is clean at every searched scale).
bool bench_buzzes(const CalibratedNote& n, double s) { return std::isfinite(n.clean_up_to) && s > n.clean_up_to; }

std::size_t disagreements_at(const std::vector<CalibratedNote>& notes, double s) {
    std::size_t count = 0;
    for (const CalibratedNote& n : notes)
        if (n.used && bench_buzzes(n, s) != n.heard.buzz) ++count;
    return count;
}

// How far an interval (low, high] lies from scale 1, as a ratio (0: it holds 1).
double distance_from_one(double low, double high) {
    if (high < 1.0) return std::log(1.0 / high);
    if (low >= 1.0) return std::log(low);
    return 0.0;
}

std::string scale_text(double s) {
    char text[32];
    std::snprintf(text, sizeof text, "%.2fx", s);
    return text;
}

std::string note_name(const HeardNote& h) {
    return h.string_name + std::to_string(h.fret) + " (" + h.attack.label + ", row " + std::to_string(h.row) + ")";
}

// Why a note disagrees at every scale of the best interval, in words.
std::string disagreement_text(const CalibratedNote& n) {
    const std::string name = note_name(n.heard);
    if (n.status == "frets out") return name + " heard clean frets out: it buzzes at every scale";
    if (n.heard.buzz)
        return name + " heard buzzing stays clean up to " +
               (std::isinf(n.clean_up_to) ? "at least " + scale_text(kCleanUpToCap) + " (as far as the bench searches)"
                                          : scale_text(n.clean_up_to));
    return name + " heard clean buzzes above " + scale_text(n.clean_up_to);
}

using Json = nlohmann::ordered_json;

Json finite_or_null(double v) { return std::isfinite(v) ? Json(v) : Json(); }

}  // namespace

std::vector<HeardNote> parse_player_report(std::string_view text, const std::string& source, const Instrument& instrument,
                                           const std::string& option) {
    const std::string where = option + " " + source;
    if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);  // the byte-order mark spreadsheets write
    std::string names;
    for (std::size_t k = 0; k < instrument.strings.size(); ++k) names += (k ? ", " : "") + instrument.strings[k].name;
    const std::size_t first = instrument.neck.capo, last = instrument.neck.fret_count;
    const std::string frets = "frets are " + std::to_string(first) + (first ? " (the capo)" : " (open)") + " to " +
                              std::to_string(last);

    std::vector<std::string> header;
    std::size_t string_col = 0, fret_col = 0, heard_col = 0, strength_col = 0;
    bool has_strength = false;
    std::vector<HeardNote> notes;
    std::size_t line_number = 0, start = 0;
    while (start <= text.size()) {
        const std::size_t end = text.find('\n', start);
        const std::string_view raw = text.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start);
        start = end == std::string_view::npos ? text.size() + 1 : end + 1;
        ++line_number;
        if (raw.size() > kMaxLineBytes)
            throw InputError(where + ": line " + std::to_string(line_number) + " is longer than " +
                             std::to_string(kMaxLineBytes) + " bytes");
        const std::string_view line = trim_blanks(raw);
        if (line.empty() || line.front() == '#') continue;
        std::vector<std::string> cells = report_cells(line);
        if (header.empty()) {
            // The first line names the columns: in any order, each once, none unknown (a
            // misspelt `strength` would otherwise leave every row at medium unnoticed).
            bool found[4] = {false, false, false, false};
            for (std::size_t c = 0; c < cells.size(); ++c) {
                const std::string name = lower_case(cells[c]);
                static const char* const known[4] = {"string", "fret", "heard", "strength"};
                std::size_t* const column[4] = {&string_col, &fret_col, &heard_col, &strength_col};
                const auto k = std::find_if(std::begin(known), std::end(known), [&](const char* n) { return name == n; });
                if (k == std::end(known))
                    throw InputError(where + ": line " + std::to_string(line_number) + ": column " + quoted_cell(cells[c]) +
                                     " is not one of the report's columns (" + kReportColumns +
                                     "); the first line names them, e.g. string,fret,heard,strength");
                const auto i = static_cast<std::size_t>(k - std::begin(known));
                if (found[i]) throw InputError(where + ": the column " + known[i] + " is named twice");
                found[i] = true;
                *column[i] = c;
            }
            for (std::size_t i = 0; i < 3; ++i)
                if (!found[i])
                    throw InputError(where + ": the first line names no column " +
                                     std::string(i == 0 ? "string" : i == 1 ? "fret" : "heard") + " (give " +
                                     kReportColumns + ", e.g. string,fret,heard,strength)");
            has_strength = found[3];
            header = std::move(cells);
            continue;
        }
        HeardNote h;
        h.row = notes.size() + 1;
        h.line = line_number;
        const std::string at = where + ": row " + std::to_string(h.row) + " (line " + std::to_string(line_number) + ")";
        if (h.row > kMaxReportRows)
            throw InputError(at + ": a report holds at most " + std::to_string(kMaxReportRows) + " rows");
        if (cells.size() > header.size())
            throw InputError(at + " has " + std::to_string(cells.size()) + " cells; the header names " +
                             std::to_string(header.size()) + " columns");
        cells.resize(header.size());  // a short row leaves its last cells empty (strength: medium)
        const std::string& name = cells[string_col];
        const auto s = std::find_if(instrument.strings.begin(), instrument.strings.end(),
                                    [&](const auto& string) { return string.name == name; });
        if (s == instrument.strings.end())
            throw InputError(at + ", column string: " + quoted_cell(name) + " is not a string of " + instrument.name +
                             " (its strings: " + names + ")");
        h.string = static_cast<std::size_t>(s - instrument.strings.begin());
        h.string_name = name;
        const std::string& fret = cells[fret_col];
        unsigned long k = 0;
        const auto [end_of, error] = std::from_chars(fret.data(), fret.data() + fret.size(), k);
        if (fret.empty() || error != std::errc() || end_of != fret.data() + fret.size() || k < first || k > last)
            throw InputError(at + ", column fret: " + quoted_cell(fret) + " is not a fret of " + instrument.name +
                             ": give a whole number; " + frets);
        h.fret = k;
        const std::string heard = lower_case(cells[heard_col]);
        if (heard != "buzz" && heard != "clean")
            throw InputError(at + ", column heard: " + quoted_cell(cells[heard_col]) + " must be buzz or clean");
        h.buzz = heard == "buzz";
        const std::string strength = has_strength && !cells[strength_col].empty() ? cells[strength_col] : "medium";
        if (strength.size() > 32)
            throw InputError(at + ", column strength: " + quoted_cell(strength) + " is not an attack; give one as " +
                             "--strength names it (soft, medium, hard, pick, pop, slap, 1.2mm, 3m/s)");
        h.attack = parse_attacks(strength, instrument.attack, at + ", column strength:").front();
        notes.push_back(std::move(h));
    }
    if (notes.empty())
        throw InputError(where + ": holds no rows: give a header (" + kReportColumns +
                         ") and one row per note heard, e.g. E,5,buzz,medium");
    return notes;
}

std::vector<HeardNote> read_player_report(const std::filesystem::path& path, const Instrument& instrument,
                                          const std::string& option) {
    const std::string text = read_text_file(path, option + " " + path.string(), kMaxCaseFileBytes);
    return parse_player_report(text, path.string(), instrument, option);
}

Calibration fit_attack_scale(std::vector<CalibratedNote> notes) {
    Calibration c;
    std::vector<double> ends{0.0, kCleanUpToCap};  // the segments' ends: (ends[i], ends[i + 1]]
    for (CalibratedNote& n : notes) {
        n.used = !std::isnan(n.clean_up_to) && (n.status == "ok" || n.status == "frets out");
        if (n.used) ends.push_back(searched(n.clean_up_to));
    }
    std::sort(ends.begin(), ends.end());
    ends.erase(std::unique(ends.begin(), ends.end()), ends.end());
    c.notes = std::move(notes);
    if (std::none_of(c.notes.begin(), c.notes.end(), [](const CalibratedNote& n) { return n.used; })) {
        c.statement = "No reported note could be played (see each note's status): no attack scale is fitted.";
        return c;
    }
    // The disagreements are constant on each segment (every clean_up_to is an end): its right
    // end, which the segment holds, stands for it.
    std::vector<std::size_t> count;
    for (std::size_t i = 0; i + 1 < ends.size(); ++i) count.push_back(disagreements_at(c.notes, ends[i + 1]));
    c.disagreements = *std::min_element(count.begin(), count.end());
    c.explained = c.disagreements == 0;
    std::vector<std::pair<double, double>> best;
    for (std::size_t i = 0; i < count.size(); ++i) {
        if (count[i] != c.disagreements) continue;
        if (!best.empty() && best.back().second == ends[i]) best.back().second = ends[i + 1];  // adjoining: one interval
        else best.emplace_back(ends[i], ends[i + 1]);
    }
    const auto nearest = std::min_element(best.begin(), best.end(), [](const auto& a, const auto& b) {
        return distance_from_one(a.first, a.second) < distance_from_one(b.first, b.second);
    });
    std::tie(c.low, c.high) = *nearest;
    for (const auto& interval : best)
        if (interval != *nearest) c.other_intervals.push_back(interval);
    c.low_bounded = c.low > 0.0;
    // The cap bounds the search, not the scale, unless a clean row is clean only up to it.
    c.high_at_least = c.high >= kCleanUpToCap && std::none_of(c.notes.begin(), c.notes.end(), [](const CalibratedNote& n) {
                          return n.used && !n.heard.buzz && n.clean_up_to == kCleanUpToCap;
                      });
    // Bounded both ways, the report pins the scale: the middle of the interval, in ratio (the
    // scales multiply). Bounded one way only, it says no more than that: the scale nearest the
    // instrument's own attack that it allows (the low end is exclusive: 1 % above it, the
    // bisection's tolerance, the note surely buzzes).
    if (c.low_bounded && !c.high_at_least) c.attack_scale = std::sqrt(c.low * c.high);
    else c.attack_scale = std::clamp(1.0, std::min(c.low * (1.0 + kCleanUpToTolerance), c.high), c.high);
    for (CalibratedNote& n : c.notes) n.agrees = n.used && bench_buzzes(n, c.attack_scale) == n.heard.buzz;

    std::size_t used = 0;
    for (const CalibratedNote& n : c.notes) used += n.used;
    std::ostringstream s;
    const std::string range = "(" + scale_text(c.low) + ", " + scale_text(c.high) + (c.high_at_least ? " or more" : "") + "]";
    if (c.explained) {
        s << "Attack scale " << scale_text(c.attack_scale) << ": every scale in " << range << " of the instrument's attacks "
          << "explains " << (used == 1 ? std::string("the one note") : "all " + std::to_string(used) + " notes") << " used.";
        const char* const nearest_one = ": the scale given is the one in the interval nearest the instrument's own attack (1x).";
        if (!c.low_bounded) s << " No note heard buzzing bounds it from below" << nearest_one;
        else if (c.high_at_least)
            s << " No note heard clean bounds it from above within the bench's search (up to " << scale_text(kCleanUpToCap)
              << ")" << nearest_one;
    } else {
        s << "No scale explains the report: at best " << c.disagreements << " of " << used << " notes disagree (at "
          << range << "; the scale given, " << scale_text(c.attack_scale) << ", is that compromise).";
        std::size_t listed = 0;
        for (const CalibratedNote& n : c.notes)
            if (n.used && !n.agrees && listed++ < 5) s << (listed == 1 ? " " : "; ") << disagreement_text(n);
        if (listed > 5) s << "; and " << listed - 5 << " more";
        s << ".";
    }
    if (!c.other_intervals.empty())
        s << " " << c.other_intervals.size() << " other interval" << (c.other_intervals.size() > 1 ? "s do" : " does")
          << " as well (other_intervals); the one nearest the instrument's attack is given.";
    if (used < c.notes.size()) s << " " << c.notes.size() - used << " notes could not be played and bound nothing.";
    c.statement = s.str();
    return c;
}

Calibration calibrate_attack(const Instrument& instrument, const std::vector<HeardNote>& report,
                             const CalibrationRequest& request) {
    const auto start = std::chrono::steady_clock::now();
    // Each attack's distinct notes, played once in one map: a note reported twice (heard again)
    // has one clean_up_to. Maps of one attack each: clean_up_to is searched up to the cap times
    // the largest attack of a map's gesture, so one attack a map keeps every row's range at 3x.
    std::vector<std::string> labels;
    std::map<std::string, std::vector<MapNote>> notes_of;
    std::map<std::string, Attack> attack_of;
    for (const HeardNote& h : report) {
        if (!attack_of.contains(h.attack.label)) {
            labels.push_back(h.attack.label);
            attack_of.emplace(h.attack.label, h.attack);
        }
        std::vector<MapNote>& notes = notes_of[h.attack.label];
        if (std::none_of(notes.begin(), notes.end(), [&](const MapNote& n) { return n.string == h.string && n.fret == h.fret; }))
            notes.push_back({h.string, h.fret});
    }
    std::size_t total = 0, done_before = 0;
    for (const auto& [label, notes] : notes_of) total += notes.size();
    std::map<std::tuple<std::string, std::size_t, std::size_t>, NoteVerdict> verdicts;
    std::size_t simulated = 0;
    for (const std::string& label : labels) {
        MapRequest map;
        map.notes = notes_of[label];
        map.attacks = {attack_of.at(label)};
        map.finger = request.finger;
        map.clean_up_to = true;
        map.jobs = request.jobs;
        if (request.on_note)
            map.on_note = [&](const NoteVerdict& v, std::size_t done, std::size_t) { request.on_note(v, done_before + done, total); };
        map.stop = request.stop;
        const BuzzMapResult result = play_map(instrument, map);
        if (result.stopped_early) throw Interrupted(stop_signal() ? stop_signal() : SIGINT);
        simulated += result.plucks_simulated;
        for (const NoteVerdict& v : result.notes) verdicts[{label, v.string, v.fret}] = v;
        done_before += map.notes.size();
    }
    std::vector<CalibratedNote> notes;
    for (const HeardNote& h : report) {
        CalibratedNote n;
        n.heard = h;
        const NoteVerdict& v = verdicts.at({h.attack.label, h.string, h.fret});
        n.status = v.status;
        n.clean_up_to = v.clean_up_to;
        notes.push_back(std::move(n));
    }
    Calibration fitted = fit_attack_scale(std::move(notes));
    fitted.plucks_simulated = simulated;
    fitted.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return fitted;
}

std::string calibration_json(const Calibration& c, const Instrument& instrument, const std::string& source,
                             const std::string& command) {
    Json notes = Json::array(), disagreeing = Json::array(), others = Json::array();
    for (const CalibratedNote& n : c.notes) {
        const bool unbounded = std::isinf(n.clean_up_to);
        Json note{{"row", n.heard.row},
                  {"string", n.heard.string_name},
                  {"fret", n.heard.fret},
                  {"strength", n.heard.attack.label},
                  {"heard", n.heard.buzz ? "buzz" : "clean"},
                  {"status", n.status},
                  {"clean_up_to", unbounded ? Json(kCleanUpToCap) : finite_or_null(n.clean_up_to)},
                  {"clean_up_to_at_least", unbounded},
                  {"used", n.used},
                  {"bench_hears", !n.used || std::isnan(c.attack_scale) ? Json()
                                                                        : Json(bench_buzzes(n, c.attack_scale) ? "buzz" : "clean")},
                  {"agrees", n.agrees}};
        if (n.used && !n.agrees)
            disagreeing.push_back(Json{{"row", n.heard.row},
                                       {"string", n.heard.string_name},
                                       {"fret", n.heard.fret},
                                       {"strength", n.heard.attack.label},
                                       {"heard", n.heard.buzz ? "buzz" : "clean"},
                                       {"why", disagreement_text(n)}});
        notes.push_back(std::move(note));
    }
    for (const auto& [low, high] : c.other_intervals) others.push_back(Json::array({low, high}));
    const Json doc{{"instrument", instrument.name},
                   {"report", source},
                   {"command", command},
                   {"rule", "at scale s a note buzzes when s > its clean_up_to (a multiple of the row's attack)"},
                   {"attack_scale", finite_or_null(c.attack_scale)},
                   {"attack_scale_low", finite_or_null(c.low)},
                   {"attack_scale_high", finite_or_null(c.high)},
                   {"attack_scale_low_bounded", c.low_bounded},
                   {"attack_scale_high_at_least", c.high_at_least},
                   {"search_cap", kCleanUpToCap},
                   {"explained", c.explained},
                   {"disagreements", c.disagreements},
                   {"statement", c.statement},
                   {"other_intervals", others},
                   {"disagreeing", disagreeing},
                   {"notes", notes},
                   {"plucks_simulated", c.plucks_simulated},
                   {"wall_seconds", c.wall_seconds}};
    return json_text(doc, 1);
}

std::string calibration_text(const Calibration& c) {
    std::ostringstream s;
    s << "calibration: " << c.statement << "\n";
    if (std::isfinite(c.attack_scale)) {
        s << "  attack scale " << scale_text(c.attack_scale) << ", interval (" << scale_text(c.low) << ", "
          << scale_text(c.high) << (c.high_at_least ? " or more" : "") << "]";
        std::size_t used = 0, agree = 0;
        for (const CalibratedNote& n : c.notes) {
            used += n.used;
            agree += n.agrees;
        }
        s << "; " << agree << " of " << used << " notes agree\n";
        s << "  play later maps at this touch with --player calibration.json\n";
    }
    return s.str();
}

PlayerTouch read_player_touch(const std::filesystem::path& path, const std::string& option) {
    const std::string where = option + " " + path.string();
    const std::string allowed = "give the calibration.json of `fretbuzz setup --calibrate`, whose attack_scale is in (0, " +
                                number_text(kMaxAttackScale) + "]";
    std::string text;
    try {
        text = read_text_file(path, where, kMaxPlayerFileBytes);
    } catch (const InputError& e) {  // (a file that cannot be read is not the user's: exit 1, untouched)
        throw InputError(std::string(e.what()) + "; " + allowed);
    }
    nlohmann::json doc;
    try {
        doc = nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception&) {
        throw InputError(where + " is not JSON; " + allowed);
    }
    if (!doc.is_object() || !doc.contains("attack_scale"))
        throw InputError(where + " holds no attack_scale; " + allowed);
    const nlohmann::json& value = doc["attack_scale"];
    if (!value.is_number())
        throw InputError(where + ": attack_scale is not a number (a calibration that could play none of its notes "
                                 "fits none); " + allowed);
    return {checked_attack_scale(where + ": attack_scale", value.get<double>()), path};
}

double checked_attack_scale(const std::string& name, double scale, const std::string& why) {
    if (!(std::isfinite(scale) && scale > 0.0 && scale <= kMaxAttackScale))
        throw InputError(out_of_range_message(name, scale, "must be in (0, " + number_text(kMaxAttackScale) + "]") + why);
    return scale;
}

void scale_attacks(std::vector<Attack>& attacks, double scale) {
    for (Attack& a : attacks) a.size *= scale;
}

}  // namespace fretbuzz
