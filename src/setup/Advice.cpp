#include "fretbuzz/setup/Advice.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "MillimetreText.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/setup/StringNeck.hpp"
#include "fretbuzz/setup/WhatIf.hpp"

namespace fretbuzz {

namespace {

constexpr double kHighestAction = 10e-3;
constexpr double kHighestRelief = 1.0e-3;

std::string note_name(const NoteVerdict& v) { return v.string_name + " " + std::to_string(v.fret); }

std::string why_text(const NoteVerdict& v) {
    std::ostringstream out;
    out << v.string_name << " fret " << v.fret << ": ";
    if (v.status != "ok")
        out << v.status << (v.buzz_fret > 0 ? " against fret " + std::to_string(v.buzz_fret) : "");
    else
        out << v.verdict << ", " << std::lround(v.buzz_fraction * static_cast<double>(v.plucks)) << "/" << v.plucks
            << " plucks buzz" << (v.buzz_fret > 0 ? " against fret " + std::to_string(v.buzz_fret) : "");
    return out.str();
}

// Not clean: buzzing, marginal (its plucks cannot show it clean) or fretting out.
bool buzzes(const NoteVerdict& v) { return v.status == "frets out" || (!v.verdict.empty() && v.verdict != "clean"); }

MapRequest probe_request(const AdviceRequest& request, std::vector<std::size_t> strings) {
    MapRequest r;
    r.strings = std::move(strings);
    r.attacks = {request.attack};
    r.finger = request.finger;
    r.jobs = request.jobs;
    r.clean_up_to = false;  // a probe asks only whether the map is clean
    return r;
}

// A search on a grid of steps: clean(i) known for each index probed, memoised.
class GridSearch {
public:
    explicit GridSearch(std::function<bool(long, std::string*)> probe) : probe_(std::move(probe)) {}
    bool clean(long i) {
        auto found = seen_.find(i);
        if (found == seen_.end()) {
            std::string why;
            const bool ok = probe_(i, &why);
            found = seen_.emplace(i, std::make_pair(ok, why)).first;
        }
        return found->second.first;
    }
    const std::string& why(long i) {
        clean(i);
        return seen_.at(i).second;
    }
    // lo not clean, hi clean: narrows them to neighbours.
    void bisect(long& lo, long& hi) {
        while (hi - lo > 1) {
            const long mid = lo + (hi - lo) / 2;
            (clean(mid) ? hi : lo) = mid;
        }
    }

private:
    std::function<bool(long, std::string*)> probe_;
    std::map<long, std::pair<bool, std::string>> seen_;
};

}  // namespace

bool map_is_clean(const Instrument& instrument, const AdviceRequest& request, std::vector<std::size_t> strings,
                  std::string* why) {
    MapRequest r = probe_request(request, std::move(strings));
    r.stop_when = buzzes;
    const BuzzMapResult result = play_map(instrument, r);
    for (const NoteVerdict& v : result.notes)
        if (buzzes(v)) {
            if (why) *why = why_text(v);
            return false;
        }
    return true;
}

ActionAdvice lowest_clean_action(const Instrument& instrument, std::size_t string, const AdviceRequest& request,
                                 std::size_t* maps) {
    ActionAdvice advice;
    const std::string& name = instrument.strings.at(string).name;
    advice.string = name;
    if (instrument.neck.fret_count < 12) {
        advice.below = "the neck has fewer than 12 frets";
        return advice;
    }
    advice.current_m = StringNeck(instrument, string).gap(12);
    GridSearch search([&](long i, std::string* why) {
        if (i < 1) {
            *why = "no action below 0.05 mm";
            return false;
        }
        SetupChange change;
        change.action12_m = {{name, static_cast<double>(i) * kActionStep}};
        Instrument changed;
        try {
            changed = apply_change(instrument, change);
        } catch (const InputError&) {
            *why = "the open string would lie on a fret";
            return false;
        }
        if (maps) ++*maps;
        return map_is_clean(changed, request, {string}, why);
    });
    const long now = std::lround(advice.current_m / kActionStep);
    const long top = std::lround(kHighestAction / kActionStep);
    long lo = 0, hi = 0;
    if (search.clean(now)) {
        hi = now;
        for (long d = 1;; d *= 2) {
            const long j = std::max(0L, hi - d);
            if (!search.clean(j)) {
                lo = j;
                break;
            }
            hi = j;
        }
    } else {
        lo = now;
        for (long d = 1;; d *= 2) {
            const long j = std::min(top, lo + d);
            if (search.clean(j)) {
                hi = j;
                break;
            }
            lo = j;
            if (j == top) return advice;  // nothing clean up to 10 mm
        }
    }
    search.bisect(lo, hi);
    advice.lowest_clean_m = static_cast<double>(hi) * kActionStep;
    advice.below = mm_text(static_cast<double>(lo) * kActionStep) + ": " + search.why(lo);
    return advice;
}

std::vector<ProudFret> proud_frets(const Instrument& instrument, const std::vector<NoteVerdict>& map,
                                   const AdviceRequest& request, std::size_t* maps) {
    std::map<std::size_t, std::vector<const NoteVerdict*>> against;  // fret -> the notes buzzing on it
    for (const NoteVerdict& v : map) {
        const bool wanted = request.strings.empty() ||
                            std::find(request.strings.begin(), request.strings.end(), v.string) != request.strings.end();
        if (wanted && v.strength == request.attack.label && buzzes(v) && v.buzz_fret > 0)
            against[static_cast<std::size_t>(v.buzz_fret)].push_back(&v);
    }
    std::vector<ProudFret> proud;
    for (const auto& [fret, notes] : against) {
        for (double by : {0.02e-3, 0.04e-3, 0.06e-3, 0.08e-3, 0.1e-3}) {
            SetupChange change;
            change.frets = {{fret, -by}};
            Instrument lowered;
            try {
                lowered = apply_change(instrument, change);
            } catch (const InputError&) {
                break;
            }
            // The notes that buzzed on it and, on their strings, the note stopped on it.
            std::map<std::size_t, std::vector<std::size_t>> to_play;
            for (const NoteVerdict* v : notes) {
                to_play[v->string].push_back(v->fret);
                to_play[v->string].push_back(fret);
            }
            ProudFret p{fret, by, {}, {}};
            bool all_cleared = true;
            for (auto& [string, frets] : to_play) {
                std::sort(frets.begin(), frets.end());
                frets.erase(std::unique(frets.begin(), frets.end()), frets.end());
                MapRequest r = probe_request(request, {string});
                r.frets = frets;
                if (maps) ++*maps;
                for (const NoteVerdict& after : play_map(lowered, r).notes) {
                    const auto old = std::find_if(map.begin(), map.end(), [&](const NoteVerdict& v) {
                        return v.string == after.string && v.fret == after.fret && v.strength == after.strength;
                    });
                    const bool was_buzzing = old != map.end() && buzzes(*old) && old->buzz_fret == static_cast<int>(fret);
                    if (was_buzzing && !buzzes(after))
                        p.cleared.push_back(note_name(after));
                    else if (was_buzzing)
                        all_cleared = false;
                    else if (old != map.end() && after.buzz_fraction > old->buzz_fraction)
                        p.worse.push_back(note_name(after));
                }
            }
            if (all_cleared && p.worse.empty()) {  // a fret merely in line moves the buzz onto its own note
                proud.push_back(p);
                break;
            }
        }
    }
    return proud;
}

ReliefAdvice clean_relief_range(const Instrument& instrument, const AdviceRequest& request, std::size_t* maps) {
    ReliefAdvice advice;
    if (instrument.neck.fret_count < 3) return advice;
    advice.fret = relief_fret(instrument);
    advice.current_m = StringNeck(instrument, 0).relief_gap(advice.fret);
    advice.searched_to_m = kHighestRelief;
    GridSearch search([&](long i, std::string* why) {
        SetupChange change;
        change.relief_m = static_cast<double>(i) * kReliefStep;
        Instrument changed;
        try {
            changed = apply_change(instrument, change);
        } catch (const InputError& e) {
            *why = e.what();
            return false;
        }
        if (maps) ++*maps;
        return map_is_clean(changed, request, request.strings, why);
    });
    const long top = std::lround(kHighestRelief / kReliefStep);
    const long now = std::clamp(std::lround(advice.current_m / kReliefStep), 0L, top);
    long inside = -1;
    if (search.clean(now)) {
        inside = now;
    } else {
        for (long i = 0; i <= top && inside < 0; i += 4)
            if (search.clean(i)) inside = i;
    }
    if (inside < 0) return advice;
    // The lower edge: from inside toward 0; the upper: toward the top of the search.
    long hi = inside, lo = -1;
    for (long d = 1;; d *= 2) {
        const long j = hi - d;
        if (j < 0) {
            if (search.clean(0)) hi = 0;
            lo = hi == 0 ? -1 : 0;
            break;
        }
        if (!search.clean(j)) {
            lo = j;
            break;
        }
        hi = j;
    }
    if (lo >= 0) search.bisect(lo, hi);
    advice.lowest_m = static_cast<double>(hi) * kReliefStep;
    long up_lo = inside, up_hi = -1;  // clean, not clean
    for (long d = 1;; d *= 2) {
        const long j = std::min(top, up_lo + d);
        if (!search.clean(j)) {
            up_hi = j;
            break;
        }
        up_lo = j;
        if (j == top) break;
    }
    if (up_hi >= 0)
        while (up_hi - up_lo > 1) {
            const long mid = up_lo + (up_hi - up_lo) / 2;
            (search.clean(mid) ? up_lo : up_hi) = mid;
        }
    advice.highest_m = static_cast<double>(up_lo) * kReliefStep;
    return advice;
}

Advice advise(const Instrument& instrument, const std::vector<NoteVerdict>& map, const AdviceRequest& request) {
    const auto start = std::chrono::steady_clock::now();
    Advice advice;
    advice.attack = request.attack;
    std::vector<std::size_t> strings = request.strings;
    if (strings.empty())
        for (std::size_t s = 0; s < instrument.strings.size(); ++s) strings.push_back(s);
    for (std::size_t s : strings) advice.actions.push_back(lowest_clean_action(instrument, s, request, &advice.maps));
    advice.proud = proud_frets(instrument, map, request, &advice.maps);
    advice.relief = clean_relief_range(instrument, request, &advice.maps);
    advice.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return advice;
}

std::string advice_json(const Advice& a) {
    using Json = nlohmann::ordered_json;
    const auto number = [](double v) { return std::isfinite(v) ? Json(v * 1e3) : Json(); };
    Json actions = Json::array();
    for (const ActionAdvice& x : a.actions)
        actions.push_back(Json{{"string", x.string},
                               {"action12_mm", number(x.current_m)},
                               {"lowest_clean_action12_mm", number(x.lowest_clean_m)},
                               {"one_step_lower", x.below}});
    Json proud = Json::array();
    for (const ProudFret& p : a.proud)
        proud.push_back(Json{{"fret", p.fret}, {"lower_by_mm", p.lower_by_m * 1e3}, {"clears", p.cleared}, {"worse", p.worse}});
    const ReliefAdvice& r = a.relief;
    return Json{{"attack", a.attack.label},
                {"step_mm", kActionStep * 1e3},
                {"lowest_action", actions},
                {"proud_frets", proud},
                {"relief",
                 Json{{"fret", r.fret},
                      {"relief_mm", number(r.current_m)},
                      {"clean_from_mm", number(r.lowest_m)},
                      {"clean_to_mm", number(r.highest_m)},
                      {"searched_mm", Json::array({r.searched_from_m * 1e3, r.searched_to_m * 1e3})}}},
                {"maps_played", a.maps},
                {"wall_seconds", a.wall_seconds}}
        .dump(1);
}

std::string advice_text(const Advice& a) {
    std::ostringstream out;
    out << "Advice at the " << a.attack.label << " attack (" << a.maps << " maps played, " << std::lround(a.wall_seconds)
        << " s):\n";
    for (const ActionAdvice& x : a.actions) {
        out << "  string " << x.string << ": action over fret 12 now " << mm_text(x.current_m) << "; ";
        if (std::isfinite(x.lowest_clean_m))
            out << "the lowest without buzz is " << mm_text(x.lowest_clean_m) << " (" << x.below << ")\n";
        else
            out << "no action up to " << mm_text(kHighestAction) << " is free of buzz" << (x.below.empty() ? "" : ": " + x.below)
                << "\n";
    }
    if (a.proud.empty())
        out << "  no fret stands proud (lowering one fret by 0.1 mm or less clears no buzz without adding some)\n";
    for (const ProudFret& p : a.proud) {
        out << "  fret " << p.fret << " stands proud: lowering it by " << mm_text(p.lower_by_m) << " clears";
        for (const std::string& n : p.cleared) out << " " << n;
        out << "\n";
    }
    const ReliefAdvice& r = a.relief;
    out << "  relief (gap at fret " << r.fret << ") now " << mm_text(r.current_m) << "; ";
    if (std::isfinite(r.lowest_m))
        out << "the map is clean from " << mm_text(r.lowest_m) << " to " << mm_text(r.highest_m)
            << (r.highest_m >= r.searched_to_m ? " (the top of the search)" : "") << "\n";
    else
        out << "no relief from 0 to " << mm_text(r.searched_to_m) << " gives a clean map\n";
    return out.str();
}

}  // namespace fretbuzz
