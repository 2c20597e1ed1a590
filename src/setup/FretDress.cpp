#include "fretbuzz/setup/FretDress.hpp"

#include <algorithm>
#include <csignal>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "MillimetreText.hpp"
#include "NoteTrials.hpp"
#include "SearchClock.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/setup/StringNeck.hpp"
#include "fretbuzz/setup/WhatIf.hpp"

namespace fretbuzz {

namespace {

constexpr std::size_t kDressRounds = 8;

// The fret tops lowered by `remove` (per fret), from the instrument as given.
Instrument lowered(const Instrument& instrument, const std::vector<double>& remove) {
    SetupChange change;
    for (std::size_t f = 1; f < remove.size(); ++f)
        if (remove[f] > 0.0) change.frets.push_back({f, -remove[f]});
    return apply_change(instrument, change);
}

long steps_of(double metres) { return static_cast<long>(std::floor(metres / kDressStep + 1e-9)); }

}  // namespace

void check_dress_request(const Instrument& instrument, const DressRequest& r) {
    const auto mm = [](double v) { return mm_text(v); };
    if (!(r.max_depth_m >= 0.01e-3 && r.max_depth_m <= 1e-3))
        throw InputError("--dress-depth = " + mm(r.max_depth_m) + " is out of range: must be in [0.01, 1] mm");
    if (r.min_crown_m && !(*r.min_crown_m >= 0.0 && *r.min_crown_m < instrument.neck.fret_height_m))
        throw InputError("--crown = " + mm(*r.min_crown_m) + " is out of range: must be in [0, " +
                         mm(instrument.neck.fret_height_m) + ") (the frets stand " + mm(instrument.neck.fret_height_m) +
                         " above the board)");
    if (r.fall_away_from && !(*r.fall_away_from >= 1 && *r.fall_away_from + 1 < instrument.neck.fret_count))
        throw InputError("--fall-away " + std::to_string(*r.fall_away_from) +
                         ": the fret it starts from must be in [1, " + std::to_string(instrument.neck.fret_count - 2) +
                         "] (it falls away over the frets past it, to the last)");
}

DressResult dress_frets(const Instrument& instrument, const std::vector<NoteVerdict>& before, const DressRequest& request) {
    check_dress_request(instrument, request);
    const SearchClock timer;
    const std::size_t last = instrument.neck.fret_count;
    DressResult d;
    d.units = instrument.units;
    d.attack = request.play.attack.label;
    d.remove_m.assign(last + 1, 0.0);
    NoteTrials trials(request.play, &d.maps);
    trials.remember(instrument, before);
    const NoteForecast forecast(instrument, before, request.play.attack);
    const std::vector<std::size_t> strings = wanted_strings(instrument, request.play);
    const std::vector<std::size_t> frets = advice_frets(instrument, request.play);
    const std::vector<MapNote> notes = notes_of(strings, frets);
    // What may come off each fret: the set depth, and its crown kept above the minimum.
    std::vector<double> room(last + 1, 0.0);
    const double min_crown = request.min_crown_m.value_or(std::min(0.75e-3, 0.5 * instrument.neck.fret_height_m));
    for (std::size_t f = 1; f <= last; ++f) {
        const auto offset = instrument.neck.fret_offset_m.find(f);
        const double crown = instrument.neck.fret_height_m + (offset == instrument.neck.fret_offset_m.end() ? 0.0 : offset->second);
        room[f] = std::max(0.0, std::min(request.max_depth_m, crown - min_crown));
    }
    std::set<std::string> unresolved;
    std::map<std::size_t, std::string> stuck;  // frets that cannot go low enough
    const auto fails_against = [&](const NoteVerdict& v, auto&& which) { return !trials.passes(v) && which(v.buzz_fret); };
    // The notes answered for on the dressed neck, the failing ones played there (the fret they buzz against matters).
    const auto now_failing = [&](const std::vector<double>& remove) {
        const Instrument at = lowered(instrument, remove);
        std::vector<NoteVerdict> failing;
        for (const NoteVerdict& v : trials.play_all(at, forecast.ordered(at, notes), false))
            if (!trials.passes(v)) failing.push_back(v);
        return failing;
    };

    if (request.fall_away_from) {
        const std::size_t from = *request.fall_away_from;
        const StringNeck neck(instrument, strings.front());
        std::vector<double> shape(last + 1, 0.0);
        double deepest = request.max_depth_m;
        for (std::size_t n = from + 1; n <= last; ++n) {
            shape[n] = (neck.fret_x(n) - neck.fret_x(from)) / (neck.fret_x(last) - neck.fret_x(from));
            deepest = std::min(deepest, room[n] / shape[n]);
        }
        const auto past = [from](int fret) { return fret > static_cast<int>(from); };
        std::vector<MapNote> targets;
        for (const NoteVerdict& v : now_failing(d.remove_m))
            if (fails_against(v, past)) targets.push_back({v.string, v.fret});
        if (!targets.empty()) {
            const auto ramp = [&](long i) {
                std::vector<double> remove(last + 1, 0.0);
                for (std::size_t n = from + 1; n <= last; ++n) remove[n] = static_cast<double>(i) * kDressStep * shape[n];
                return remove;
            };
            const long most = steps_of(deepest);
            const long depth = lowest_holding(1, most, [&](long i) {
                const auto heard = trials.play(lowered(instrument, ramp(i)), targets,
                                               [&](const NoteVerdict& v) { return fails_against(v, past); }, false);
                return std::none_of(heard.begin(), heard.end(), [&](const NoteVerdict& v) { return fails_against(v, past); });
            });
            if (depth <= most) {
                d.remove_m = ramp(depth);
                d.fall_away_from = from;
                d.fall_away_m = static_cast<double>(depth) * kDressStep;
            } else {
                unresolved.insert("a fall-away from fret " + std::to_string(from) + " of up to " +
                                  mm_text(static_cast<double>(most) * kDressStep) +
                                  " at the last fret does not stop the notes buzzing against the frets past it");
            }
        }
    }

    for (std::size_t round = 0; round < kDressRounds; ++round) {
        std::map<std::size_t, std::vector<MapNote>> against;  // fret -> the notes failing against it
        for (const NoteVerdict& v : now_failing(d.remove_m)) {
            if (v.status == "ok" && v.buzz_fraction == 0.0)  // marginal only for want of plucks: no fret is at fault
                unresolved.insert(failure_text(v) + ": none of its plucks buzzes, too few of them to call it clean "
                                                    "(a larger ensemble)");
            else if (v.buzz_fret > 0)
                against[static_cast<std::size_t>(v.buzz_fret)].push_back({v.string, v.fret});
            else
                unresolved.insert(failure_text(v) + ": no fret work clears it");
        }
        bool progress = false;
        // Ascending, so that a note a lowered fret hands to the next fret is dealt with this round.
        for (auto group = against.begin(); group != against.end(); ++group) {
            const std::size_t fret = group->first;
            const std::vector<MapNote>& failing = group->second;
            // A fret not touched yet takes at least what a fret file takes in one go.
            const long first = d.remove_m[fret] > 0.0 ? 1 : steps_of(kFileCut);
            const long most = steps_of(room[fret] - d.remove_m[fret]);
            const auto on_this = [f = static_cast<int>(fret)](int buzz_fret) { return buzz_fret == f; };
            const auto with = [&](long i) {
                std::vector<double> remove = d.remove_m;
                remove[fret] += static_cast<double>(i) * kDressStep;
                return remove;
            };
            const auto holds = [&](long i) {
                const auto heard = trials.play(lowered(instrument, with(i)), failing,
                                               [&](const NoteVerdict& v) { return fails_against(v, on_this); }, false);
                return std::none_of(heard.begin(), heard.end(), [&](const NoteVerdict& v) { return fails_against(v, on_this); });
            };
            // Where the notes' clean_up_to says they would pass (geometry only), to start from.
            const long guess = lowest_holding(first, most, [&](long i) {
                const Instrument at = lowered(instrument, with(i));
                for (const MapNote& n : failing)
                    if (forecast.up_to(StringNeck(at, n.string), n.string, n.fret) < 1.0) return false;
                return true;
            });
            const long depth = most < first ? most + 1 : lowest_holding(first, most, holds, std::min(guess, most));
            if (depth > most) {  // said once per fret, with the notes of the last round that tried it
                std::ostringstream why;
                why << "fret " << fret << ": ";
                if (d.remove_m[fret] > 0.0)  // what comes off it cleared other notes; these need more
                    why << mm_text(d.remove_m[fret]) << " comes off it for the notes it clears, but ";
                why << "taking " << mm_text(room[fret]) << " off (the most allowed) does not stop";
                for (const MapNote& n : failing) why << " " << instrument.strings[n.string].name << " " << n.fret;
                why << " buzzing against it";
                stuck[fret] = why.str();
                continue;
            }
            stuck.erase(fret);
            d.remove_m[fret] += static_cast<double>(depth) * kDressStep;
            progress = true;
            // The notes stopped on it and next to it start lower now: one that fails against a
            // fret further up joins that fret's group.
            std::vector<MapNote> moved;
            for (std::size_t s : strings)
                for (std::size_t k : {fret - 1, fret})
                    if (std::find(frets.begin(), frets.end(), k) != frets.end()) moved.push_back({s, k});
            for (const NoteVerdict& v : trials.play_all(lowered(instrument, d.remove_m), moved, false))
                if (!trials.passes(v) && v.buzz_fret > static_cast<int>(fret)) {
                    std::vector<MapNote>& later = against[static_cast<std::size_t>(v.buzz_fret)];
                    if (std::none_of(later.begin(), later.end(),
                                     [&](const MapNote& n) { return n.string == v.string && n.fret == v.fret; }))
                        later.push_back({v.string, v.fret});
                }
        }
        if (!progress) break;
    }

    for (const auto& [fret, why] : stuck) unresolved.insert(why);
    d.dressed = lowered(instrument, d.remove_m);
    MapRequest after;
    after.notes = notes;
    after.attacks = {request.play.attack};
    after.finger = request.play.finger;
    after.jobs = request.play.jobs;
    after.stop = request.play.stop;
    ++d.maps;
    d.after = play_map(d.dressed, after).notes;
    if (request.play.stop && request.play.stop()) throw Interrupted(SIGINT);
    d.clean = std::all_of(d.after.begin(), d.after.end(), [&](const NoteVerdict& v) { return trials.passes(v); });
    // What still fails, in words (a probe may have passed it where the whole map does not).
    for (const NoteVerdict& v : d.after)
        if (!trials.passes(v) && unresolved.empty()) unresolved.insert(failure_text(v) + " after the dress");
    d.unresolved.assign(unresolved.begin(), unresolved.end());
    d.wall_seconds = timer.wall_seconds();
    d.cpu_seconds = timer.cpu_seconds();
    return d;
}

std::string dress_csv(const DressResult& d) {
    std::ostringstream out;
    out << "fret,remove_mm,remove_thou\n";
    out.precision(6);
    for (std::size_t f = 1; f < d.remove_m.size(); ++f)
        out << f << "," << std::fixed << d.remove_m[f] * 1e3 << "," << d.remove_m[f] / kInch * 1e3 << std::defaultfloat
            << "\n";
    return out.str();
}

std::string dress_json(const DressResult& d) {
    using Json = nlohmann::ordered_json;
    Json frets = Json::array();
    double total = 0.0;
    for (std::size_t f = 1; f < d.remove_m.size(); ++f) {
        total += d.remove_m[f];
        frets.push_back(Json{{"fret", f}, {"remove_mm", d.remove_m[f] * 1e3}, {"remove_in", d.remove_m[f] / kInch}});
    }
    return Json{{"attack", d.attack},
                {"units", units_name(d.units)},
                {"frets", frets},
                {"total_mm", total * 1e3},
                {"fall_away", d.fall_away_from ? Json{{"from_fret", d.fall_away_from},
                                                      {"depth_mm", d.fall_away_m * 1e3},
                                                      {"depth_in", d.fall_away_m / kInch}}
                                               : Json()},
                {"clean", d.clean},
                {"unresolved", d.unresolved},
                {"maps_played", d.maps},
                {"wall_seconds", d.wall_seconds},
                {"cpu_seconds", d.cpu_seconds}}
        .dump(1);
}

std::string dress_text(const DressResult& d) {
    std::ostringstream out;
    out << "Fret dress at the " << d.attack << " attack (" << d.maps << " probes played, " << std::lround(d.wall_seconds)
        << " s):\n";
    if (d.fall_away_from)
        out << "  a fall-away from fret " << d.fall_away_from << ", " << shop_text(d.fall_away_m, fine_units(d.units))
            << " at the last fret\n";
    bool any = false;
    for (std::size_t f = 1; f < d.remove_m.size(); ++f)
        if (d.remove_m[f] > 0.0) {
            out << "  fret " << f << ": take " << shop_text(d.remove_m[f], fine_units(d.units)) << " off\n";
            any = true;
        }
    if (!any) out << "  nothing to take off: every note passes as the frets are\n";
    for (const std::string& u : d.unresolved) out << "  not cleared: " << u << "\n";
    out << (d.clean ? "  after it, every note passes\n" : "  after it, some notes still buzz (see above)\n");
    return out.str();
}

}  // namespace fretbuzz
