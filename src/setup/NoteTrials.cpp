#include "NoteTrials.hpp"

#include <algorithm>
#include <csignal>
#include <cmath>
#include <limits>
#include <sstream>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/setup/NoteJudge.hpp"
#include "fretbuzz/setup/PluckReach.hpp"

namespace fretbuzz {

namespace {

constexpr double kSameClearance = 1e-9;  // m: geometry computed twice agrees far better

std::vector<double> clearances(const StringNeck& neck, std::size_t fret) {
    std::vector<double> g;
    for (std::size_t n = fret + 1; n <= neck.fret_count(); ++n) g.push_back(neck.clearance(fret, n));
    return g;
}

std::string against_text(int fret) {
    return fret > 0 ? " against fret " + std::to_string(fret) : fret == kBoard ? " against the board" : "";
}

}  // namespace

bool NoteTrials::passes(const NoteVerdict& v) const {
    if (v.status == "frets out") return false;
    if (v.verdict.empty()) return true;  // not played (a pluck behind the fret): nothing to hear
    return v.verdict == "clean" || (request_.tolerate.marginal && v.verdict == "marginal");
}

void NoteTrials::remember(const Instrument& instrument, const std::vector<NoteVerdict>& map) {
    std::map<std::size_t, StringNeck> necks;
    for (const NoteVerdict& v : map) {
        if (v.strength != request_.attack.label || v.string_name.empty() || v.string >= instrument.strings.size() ||
            (v.verdict.empty() && v.status != "frets out"))
            continue;
        auto neck = necks.find(v.string);
        if (neck == necks.end()) neck = necks.emplace(v.string, StringNeck(instrument, v.string)).first;
        trials_.push_back({v.string, v.fret, clearances(neck->second, v.fret), passes(v), v});
    }
}

const NoteTrials::Trial* NoteTrials::recall(const MapNote& note, const std::vector<double>& clearance,
                                           bool failures) const {
    for (const Trial& t : trials_) {
        if (t.string != note.string || t.fret != note.fret || t.clearance.size() != clearance.size()) continue;
        bool follows = true;
        for (std::size_t n = 0; n < clearance.size() && follows; ++n) {
            const double d = clearance[n] - t.clearance[n];
            follows = t.passed ? d >= -kSameClearance : failures ? d <= kSameClearance : std::abs(d) <= kSameClearance;
        }
        if (follows) return &t;
    }
    return nullptr;
}

std::vector<NoteVerdict> NoteTrials::play(const Instrument& instrument, const std::vector<MapNote>& notes,
                                          const std::function<bool(const NoteVerdict&)>& bad, bool recall_failures) {
    std::map<std::size_t, StringNeck> necks;
    std::vector<NoteVerdict> out;
    std::vector<MapNote> unknown;
    std::vector<std::vector<double>> unknown_clearance;
    for (const MapNote& n : notes) {
        auto neck = necks.find(n.string);
        if (neck == necks.end()) neck = necks.emplace(n.string, StringNeck(instrument, n.string)).first;
        std::vector<double> g = clearances(neck->second, n.fret);
        if (const Trial* t = recall(n, g, recall_failures)) {
            out.push_back(t->verdict);
            if (bad(t->verdict)) return out;  // no note need be played
            continue;
        }
        unknown.push_back(n);
        unknown_clearance.push_back(std::move(g));
    }
    if (unknown.empty()) return out;
    MapRequest r;
    r.notes = unknown;
    r.attacks = {request_.attack};
    r.finger = request_.finger;
    r.jobs = request_.jobs;
    r.clean_up_to = false;  // a probe asks only whether the notes pass
    r.stop_when = bad;
    r.stop = request_.stop;
    if (maps_) ++*maps_;
    if (request_.on_note)
        r.on_note = [this](const NoteVerdict& v, std::size_t, std::size_t) { request_.on_note(v, maps_ ? *maps_ : 0); };
    const BuzzMapResult played = play_map(instrument, r);
    if (request_.stop && request_.stop()) throw Interrupted(SIGINT);  // a probe cut short answers nothing
    for (std::size_t i = 0; i < unknown.size(); ++i)
        for (const NoteVerdict& v : played.notes)
            if (v.string == unknown[i].string && v.fret == unknown[i].fret) {
                trials_.push_back({v.string, v.fret, unknown_clearance[i], passes(v), v});
                out.push_back(v);
            }
    return out;
}

std::optional<NoteVerdict> NoteTrials::first_failure(const Instrument& instrument, const std::vector<MapNote>& notes) {
    for (const NoteVerdict& v : play(instrument, notes, [this](const NoteVerdict& v) { return !passes(v); }))
        if (!passes(v)) return v;
    return std::nullopt;
}

NoteForecast::NoteForecast(const Instrument& instrument, const std::vector<NoteVerdict>& map, const Attack& attack)
    : pluck_from_bridge_m_(attack.where.from_bridge_m) {
    for (const NoteVerdict& v : map) {
        if (v.strength != attack.label || v.string >= instrument.strings.size() || v.string_name.empty()) continue;
        if (v.status == "frets out")
            up_to_[{v.string, v.fret}] = 0.0;
        else if (!std::isnan(v.clean_up_to))
            up_to_[{v.string, v.fret}] = v.clean_up_to;
        else
            continue;
        if (!necks_.contains(v.string)) necks_.emplace(v.string, StringNeck(instrument, v.string));
    }
}

double NoteForecast::up_to(const StringNeck& changed, std::size_t string, std::size_t fret) const {
    const auto found = up_to_.find({string, fret});
    if (found == up_to_.end()) return std::numeric_limits<double>::quiet_NaN();
    if (found->second == 0.0)  // it fretted out: nothing known but whether it still rests on a fret
        return reach_margin(changed, fret, pluck_from_bridge_m_) > 0.0 ? std::numeric_limits<double>::quiet_NaN() : 0.0;
    return predicted_clean_up_to(found->second, kCleanUpToCap, necks_.at(string), changed, fret, pluck_from_bridge_m_);
}

bool NoteForecast::passes(const StringNeck& changed, std::size_t string, const std::vector<std::size_t>& frets) const {
    for (std::size_t k : frets)
        if (up_to(changed, string, k) < 1.0) return false;
    return true;
}

std::vector<MapNote> NoteForecast::ordered(const Instrument& changed, const std::vector<MapNote>& notes) const {
    std::map<std::size_t, StringNeck> necks;
    std::vector<std::pair<double, MapNote>> keyed;
    for (const MapNote& n : notes) {
        auto neck = necks.find(n.string);
        if (neck == necks.end()) neck = necks.emplace(n.string, StringNeck(changed, n.string)).first;
        const double u = up_to(neck->second, n.string, n.fret);
        keyed.push_back({std::isnan(u) ? 0.5 : u, n});
    }
    std::stable_sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<MapNote> out;
    for (const auto& [key, n] : keyed) out.push_back(n);
    return out;
}

std::vector<std::size_t> wanted_strings(const Instrument& instrument, const AdviceRequest& request) {
    std::vector<std::size_t> strings = request.strings;
    if (strings.empty())
        for (std::size_t s = 0; s < instrument.strings.size(); ++s) strings.push_back(s);
    return strings;
}

std::vector<MapNote> notes_of(const std::vector<std::size_t>& strings, const std::vector<std::size_t>& frets) {
    std::vector<MapNote> notes;
    for (std::size_t s : strings)
        for (std::size_t k : frets) notes.push_back({s, k});
    return notes;
}

std::string note_name(const NoteVerdict& v) { return v.string_name + " " + std::to_string(v.fret); }

std::string failure_text(const NoteVerdict& v) {
    std::ostringstream out;
    out << v.string_name << " fret " << v.fret << ": ";
    if (v.status != "ok")
        out << v.status << against_text(v.buzz_fret);
    else
        out << v.verdict << ", " << std::lround(v.buzz_fraction * static_cast<double>(v.plucks)) << "/" << v.plucks
            << " plucks buzz" << against_text(v.buzz_fret);
    return out.str();
}

std::optional<Instrument> changed_or_none(const Instrument& instrument, const SetupChange& change) {
    try {
        return apply_change(instrument, change);
    } catch (const InputError&) {
        return std::nullopt;
    }
}

long lowest_holding(long low, long high, const std::function<bool(long)>& holds, long guess) {
    if (low > high) return high + 1;
    long fails = low - 1, passes = high + 1;  // known: fails at `fails`, holds at `passes`
    if (guess >= low && guess <= high) {
        if (holds(guess)) {
            passes = guess;
            for (long d = 1; passes > low; d *= 2) {
                const long j = std::max(low, passes - d);
                if (!holds(j)) {
                    fails = j;
                    break;
                }
                passes = j;
            }
        } else {
            fails = guess;
            for (long d = 1; fails < high; d *= 2) {
                const long j = std::min(high, fails + d);
                if (holds(j)) {
                    passes = j;
                    break;
                }
                fails = j;
            }
        }
    } else if (holds(high)) {
        passes = high;
    } else {
        return high + 1;
    }
    if (passes > high) return high + 1;
    while (passes - fails > 1) {
        const long mid = fails + (passes - fails) / 2;
        (holds(mid) ? passes : fails) = mid;
    }
    return passes;
}

}  // namespace fretbuzz
