#include "fretbuzz/setup/Advice.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "MillimetreText.hpp"
#include "NoteTrials.hpp"
#include "SearchClock.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/setup/NoteJudge.hpp"
#include "fretbuzz/setup/PluckReach.hpp"
#include "fretbuzz/setup/StringNeck.hpp"
#include "fretbuzz/setup/WhatIf.hpp"

namespace fretbuzz {

namespace {

constexpr double kHighestAction = 10e-3;
constexpr double kHighestRelief = 1.0e-3;
constexpr double kFallAwayStep = 0.01e-3;
constexpr double kDeepestFallAway = 0.5e-3;

ActionAdvice action_search(const Instrument& instrument, std::size_t string, const AdviceRequest& request,
                           const NoteForecast& forecast, NoteTrials& trials) {
    ActionAdvice advice;
    const std::string& name = instrument.strings.at(string).name;
    advice.string = name;
    if (instrument.neck.fret_count < 12) {
        advice.below = "the neck has fewer than 12 frets";
        return advice;
    }
    const StringNeck now(instrument, string);
    advice.current_m = now.gap(12);
    // The search moves the gap at fret 12; the answer is said where the file measures too.
    const std::size_t measured = instrument.strings.at(string).action_fret;
    advice.measured_fret = measured >= 2 && measured <= instrument.neck.fret_count ? measured : 12;
    advice.current_at_measured_m = now.gap(advice.measured_fret);
    const std::vector<std::size_t> frets = advice_frets(instrument, request);
    if (frets.empty()) {
        advice.below = "no note to answer for";
        return advice;
    }
    const auto at = [&](long i) {
        SetupChange change;
        change.action_m = {{name, 12, static_cast<double>(i) * kActionStep}};
        return changed_or_none(instrument, change);
    };
    const long top = std::lround(kHighestAction / kActionStep);
    long start = std::lround(advice.current_m / kActionStep);
    if (forecast.usable()) {
        const long predicted = lowest_holding(1, top, [&](long i) {
            const auto changed = at(i);
            return changed && forecast.passes(StringNeck(*changed, string), string, frets);
        });
        if (predicted <= top) {
            start = predicted;
            advice.predicted_m = static_cast<double>(predicted) * kActionStep;
        }
    }
    std::map<long, std::optional<NoteVerdict>> failed;
    std::map<long, std::string> why;
    const auto passes = [&](long i) {
        if (const auto seen = failed.find(i); seen != failed.end()) return !seen->second && !why.contains(i);
        if (i < 1) {
            why[i] = "no action below " + mm_text(kActionStep);
            failed[i] = std::nullopt;
            return false;
        }
        const auto changed = at(i);
        if (!changed) {
            why[i] = "the open string would lie on a fret";
            failed[i] = std::nullopt;
            return false;
        }
        const auto failure = trials.first_failure(*changed, forecast.ordered(*changed, notes_of({string}, frets)));
        failed[i] = failure;
        if (failure) why[i] = failure_text(*failure);
        return !failure;
    };
    const long hi = lowest_holding(1, top, passes, start);
    if (hi > top) {
        advice.below = mm_text(kHighestAction) + ": " + why[top];
        return advice;  // nothing passes up to 10 mm
    }
    const long lo = hi - 1;
    passes(lo);  // known already, but for the lowest grid step
    advice.lowest_clean_m = static_cast<double>(hi) * kActionStep;
    const StringNeck lowest(*at(hi), string);
    advice.saddle_change_m = lowest.saddle_height() - now.saddle_height();
    advice.lowest_clean_at_measured_m = lowest.gap(advice.measured_fret);
    advice.beyond_setup = std::abs(advice.saddle_change_m) > kSetupSaddleMove + 1e-12;
    advice.below = mm_text(static_cast<double>(lo) * kActionStep) + ": " + why[lo];
    if (const auto& f = failed[lo]) {
        advice.limiting_fret = f->fret;
        advice.limiting_against = f->buzz_fret;
    }
    return advice;
}

// Where the upper frets set the action: the fall-away predicted to let the string down to
// what the frets up to kUpperFrets allow.
std::optional<FallAwayAdvice> fall_away_prediction(const Instrument& instrument, std::size_t string,
                                                   const ActionAdvice& action, const AdviceRequest& request,
                                                   const NoteForecast& forecast) {
    if (!forecast.usable() || !std::isfinite(action.lowest_clean_m) || action.limiting_fret <= kUpperFrets)
        return std::nullopt;
    std::vector<std::size_t> lower, all = advice_frets(instrument, request);
    for (std::size_t k : all)
        if (k <= kUpperFrets) lower.push_back(k);
    const std::string& name = instrument.strings[string].name;
    const auto at = [&](double action_m, std::size_t from, double depth) {
        SetupChange change;
        change.action_m = {{name, 12, action_m}};
        if (depth > 0.0) {
            const StringNeck neck(instrument, string);
            const std::size_t last = neck.fret_count();
            for (std::size_t n = from + 1; n <= last; ++n)
                change.frets.push_back(
                    {n, -depth * (neck.fret_x(n) - neck.fret_x(from)) / (neck.fret_x(last) - neck.fret_x(from))});
        }
        return changed_or_none(instrument, change);
    };
    const long now = std::lround(action.lowest_clean_m / kActionStep);
    const long low = lowest_holding(1, now, [&](long i) {
        const auto changed = at(static_cast<double>(i) * kActionStep, 0, 0.0);
        return changed && forecast.passes(StringNeck(*changed, string), string, lower);
    });
    if (low > now - 2) return std::nullopt;  // the lower frets allow no 0.1 mm less
    FallAwayAdvice advice;
    advice.string = name;
    advice.limiting_fret = action.limiting_fret;
    advice.action_now_m = action.lowest_clean_m;
    advice.lower_frets_m = static_cast<double>(low) * kActionStep;
    // From the lowest upper note predicted to fail there: the frets past it fall away.
    const auto flat = at(advice.lower_frets_m, 0, 0.0);
    if (!flat) return std::nullopt;
    const StringNeck flat_neck(*flat, string);
    advice.from_fret = instrument.neck.fret_count;
    for (std::size_t k : all)
        if (k > kUpperFrets && forecast.up_to(flat_neck, string, k) < 1.0) advice.from_fret = std::min(advice.from_fret, k);
    if (advice.from_fret >= instrument.neck.fret_count) return std::nullopt;
    const long deepest = std::lround(kDeepestFallAway / kFallAwayStep);
    const long depth = lowest_holding(1, deepest, [&](long i) {
        const auto changed = at(advice.lower_frets_m, advice.from_fret, static_cast<double>(i) * kFallAwayStep);
        return changed && forecast.passes(StringNeck(*changed, string), string, all);
    });
    if (depth > deepest) return std::nullopt;
    advice.depth_m = static_cast<double>(depth) * kFallAwayStep;
    return advice;
}

std::vector<ProudFret> proud_search(const Instrument& instrument, const std::vector<NoteVerdict>& map,
                                    const AdviceRequest& request, NoteTrials& trials) {
    const std::vector<std::size_t> strings = wanted_strings(instrument, request);
    const std::vector<std::size_t> frets = advice_frets(instrument, request);
    const auto wanted = [&](const NoteVerdict& v) {
        return v.strength == request.attack.label && std::find(strings.begin(), strings.end(), v.string) != strings.end() &&
               std::find(frets.begin(), frets.end(), v.fret) != frets.end();
    };
    const auto before = [&](std::size_t string, std::size_t fret) -> const NoteVerdict* {
        for (const NoteVerdict& v : map)
            if (wanted(v) && v.string == string && v.fret == fret) return &v;
        return nullptr;
    };
    std::map<std::size_t, std::vector<const NoteVerdict*>> against;  // fret -> the notes failing on it
    for (const NoteVerdict& v : map)
        if (wanted(v) && !trials.passes(v) && v.buzz_fret > 0) against[static_cast<std::size_t>(v.buzz_fret)].push_back(&v);
    std::vector<ProudFret> proud;
    for (const auto& [fret, notes] : against) {
        // A fret in line with its neighbours is no fault, whatever buzzes against it.
        const double height = proud_height(instrument, fret);
        if (height < kProudHeight) continue;
        SetupChange level;
        level.frets = {{fret, std::nullopt}};
        const auto levelled = changed_or_none(instrument, level);
        if (!levelled) continue;
        std::vector<MapNote> to_play;
        const auto add = [&](std::size_t string, std::size_t k) {
            const bool asked = std::find(frets.begin(), frets.end(), k) != frets.end();
            const bool have = std::any_of(to_play.begin(), to_play.end(),
                                          [&](const MapNote& n) { return n.string == string && n.fret == k; });
            if (asked && !have) to_play.push_back({string, k});
        };
        for (const NoteVerdict* v : notes) {
            add(v->string, v->fret);
            add(v->string, fret - 1);  // the notes stopped next to it: the levelled fret is now lower
            add(v->string, fret);
        }
        ProudFret p{fret, height, {}, {}};
        for (const NoteVerdict& after : trials.play_all(*levelled, to_play)) {
            const NoteVerdict* was = before(after.string, after.fret);
            const bool failed_before = was && !trials.passes(*was);
            if (failed_before && trials.passes(after)) p.cleared.push_back(note_name(after));
            if (!failed_before && !trials.passes(after)) p.worse.push_back(note_name(after));
        }
        if (!p.cleared.empty() && p.worse.empty()) proud.push_back(p);
    }
    return proud;
}

ReliefAdvice relief_search(const Instrument& instrument, const AdviceRequest& request, const NoteForecast& forecast,
                           NoteTrials& trials) {
    ReliefAdvice advice;
    if (instrument.neck.fret_count < 3) return advice;
    advice.fret = relief_fret(instrument);
    advice.current_m = StringNeck(instrument, 0).relief_gap(advice.fret);
    advice.searched_to_m = kHighestRelief;
    const std::vector<std::size_t> strings = wanted_strings(instrument, request);
    const std::vector<std::size_t> frets = advice_frets(instrument, request);
    const std::vector<MapNote> notes = notes_of(strings, frets);
    const auto failing = [&](const Instrument& at) {
        std::size_t count = 0;
        for (const NoteVerdict& v : trials.play_all(at, forecast.ordered(at, notes)))
            count += trials.passes(v) ? 0 : 1;
        return count;
    };
    advice.failing_now = failing(instrument);  // the map's own notes, recalled
    advice.best_m = advice.current_m;
    advice.failing_best = advice.failing_now;
    advice.played = true;
    if (!forecast.usable()) return advice;
    // Each relief on the grid, predicted: how many notes fail, and the closest call.
    struct Predicted {
        long i;
        std::size_t failing;
        double closest;
    };
    std::vector<Predicted> grid;
    const long top = std::lround(kHighestRelief / kReliefStep);
    for (long i = 0; i <= top; ++i) {
        SetupChange change;
        change.relief_m = static_cast<double>(i) * kReliefStep;
        const auto changed = changed_or_none(instrument, change);
        if (!changed) continue;
        Predicted p{i, 0, std::numeric_limits<double>::infinity()};
        for (std::size_t s : strings) {
            const StringNeck neck(*changed, s);
            for (std::size_t k : frets) {
                const double u = forecast.up_to(neck, s, k);
                if (std::isnan(u)) continue;
                p.failing += u < 1.0 ? 1 : 0;
                p.closest = std::min(p.closest, u);
            }
        }
        grid.push_back(p);
    }
    if (grid.empty()) return advice;
    const long now = std::lround(advice.current_m / kReliefStep);
    const auto best = std::min_element(grid.begin(), grid.end(), [&](const Predicted& a, const Predicted& b) {
        if (a.failing != b.failing) return a.failing < b.failing;
        if (a.closest != b.closest) return a.closest > b.closest;
        return std::abs(a.i - now) < std::abs(b.i - now);
    });
    if (best->failing == 0) {
        auto lo = best, hi = best;
        while (lo != grid.begin() && std::prev(lo)->failing == 0 && std::prev(lo)->i == lo->i - 1) --lo;
        while (std::next(hi) != grid.end() && std::next(hi)->failing == 0 && std::next(hi)->i == hi->i + 1) ++hi;
        advice.predicted_from_m = static_cast<double>(lo->i) * kReliefStep;
        advice.predicted_to_m = static_cast<double>(hi->i) * kReliefStep;
    }
    if (best->i == now) return advice;
    SetupChange change;
    change.relief_m = static_cast<double>(best->i) * kReliefStep;
    const std::size_t played = failing(apply_change(instrument, change));
    if (played < advice.failing_now || (played == advice.failing_now && best->failing < advice.failing_now)) {
        advice.best_m = static_cast<double>(best->i) * kReliefStep;
        advice.failing_best = played;
        advice.beyond_setup = advice.best_m > kSetupReliefMax + 1e-12 || advice.best_m < 0.0;
    }
    return advice;
}

std::string fret_list_text(const std::vector<std::size_t>& frets) {
    std::string out;
    for (std::size_t i = 0; i < frets.size();) {
        std::size_t j = i;
        while (j + 1 < frets.size() && frets[j + 1] == frets[j] + 1) ++j;
        if (!out.empty()) out += ',';
        out += std::to_string(frets[i]);
        if (j > i) out += '-' + std::to_string(frets[j]);
        i = j + 1;
    }
    return out;
}

}  // namespace

std::string AdviceTolerance::text() const {
    std::string out;
    if (marginal) out = "marginal notes";
    if (above_fret) out += (out.empty() ? "" : ", ") + std::string("notes above fret ") + std::to_string(*above_fret);
    if (practice && !out.empty()) out += " (as set-ups do; --tolerate none asks every note)";
    return out;
}

AdviceTolerance setup_practice_tolerance(const Instrument& instrument) {
    AdviceTolerance t;
    t.marginal = true;
    t.practice = true;
    double longest = 0.0;  // a multiscale neck's bass side
    for (const InstrumentString& s : instrument.strings) longest = std::max(longest, s.scale_length_m);
    if (longest >= kBassScale - 1e-9 && instrument.neck.fret_count > kBassPlayedFrets)
        t.above_fret = kBassPlayedFrets;
    return t;
}

AdviceTolerance tolerance_for(const Instrument& instrument, const std::string& text, const std::string& option) {
    return text.empty() ? setup_practice_tolerance(instrument)
                        : parse_tolerance(text, instrument.neck.fret_count, option);
}

AdviceTolerance parse_tolerance(const std::string& text, std::size_t fret_count, const std::string& option) {
    AdviceTolerance t;
    if (text == "none") return t;
    const std::string forms = "give none (every note must be clean), marginal (marginal notes pass), above=K (notes "
                              "above fret K may buzz, K in [0, " +
                              std::to_string(fret_count) + "]), or both, e.g. marginal,above=15";
    std::size_t start = 0;
    while (start <= text.size()) {
        const std::size_t comma = std::min(text.find(',', start), text.size());
        const std::string item = text.substr(start, comma - start);
        start = comma + 1;
        if (item == "marginal") {
            t.marginal = true;
            continue;
        }
        if (item.starts_with("above=")) {
            const std::string number = item.substr(6);
            std::size_t k = 0;
            const auto [end, error] = std::from_chars(number.data(), number.data() + number.size(), k);
            if (error == std::errc() && end == number.data() + number.size() && !number.empty() && k <= fret_count) {
                t.above_fret = k;
                continue;
            }
            throw InputError(option + " " + item + ": the fret must be a whole number in [0, " + std::to_string(fret_count) +
                             "]");
        }
        throw InputError(option + " " + (item.empty() ? "\"\"" : item) + ": " + forms);
    }
    return t;
}

std::vector<std::size_t> advice_frets(const Instrument& instrument, const AdviceRequest& request) {
    std::vector<std::size_t> frets = request.frets;
    if (frets.empty())
        for (std::size_t k = instrument.neck.capo; k <= instrument.neck.fret_count; ++k) frets.push_back(k);
    std::erase_if(frets, [&](std::size_t k) { return request.tolerate.ignores(k); });
    return frets;
}

bool map_is_clean(const Instrument& instrument, const AdviceRequest& request, std::vector<std::size_t> strings,
                  std::string* why) {
    NoteTrials trials(request, nullptr);
    if (strings.empty())
        for (std::size_t s = 0; s < instrument.strings.size(); ++s) strings.push_back(s);
    std::vector<MapNote> notes;
    for (std::size_t s : strings)
        for (std::size_t k : advice_frets(instrument, request)) notes.push_back({s, k});
    const auto failure = trials.first_failure(instrument, notes);
    if (failure && why) *why = failure_text(*failure);
    return !failure;
}

ActionAdvice lowest_clean_action(const Instrument& instrument, std::size_t string, const AdviceRequest& request,
                                 const std::vector<NoteVerdict>& map, std::size_t* maps) {
    NoteTrials trials(request, maps);
    trials.remember(instrument, map);
    return action_search(instrument, string, request, NoteForecast(instrument, map, request.attack), trials);
}

std::vector<ProudFret> proud_frets(const Instrument& instrument, const std::vector<NoteVerdict>& map,
                                   const AdviceRequest& request, std::size_t* maps) {
    NoteTrials trials(request, maps);
    trials.remember(instrument, map);
    return proud_search(instrument, map, request, trials);
}

ReliefAdvice best_relief(const Instrument& instrument, const std::vector<NoteVerdict>& map, const AdviceRequest& request,
                         std::size_t* maps) {
    NoteTrials trials(request, maps);
    trials.remember(instrument, map);
    return relief_search(instrument, request, NoteForecast(instrument, map, request.attack), trials);
}

Advice advise(const Instrument& instrument, const std::vector<NoteVerdict>& map, const AdviceRequest& request) {
    const SearchClock timer;
    Advice advice;
    advice.attack = request.attack;
    advice.units = instrument.units;
    advice.adjusters = instrument.adjusters;
    advice.frets = fret_list_text(advice_frets(instrument, request));
    advice.tolerated = request.tolerate.text();
    NoteTrials trials(request, &advice.maps);
    trials.remember(instrument, map);
    const NoteForecast forecast(instrument, map, request.attack);
    for (std::size_t s : wanted_strings(instrument, request)) {
        advice.actions.push_back(action_search(instrument, s, request, forecast, trials));
        if (auto f = fall_away_prediction(instrument, s, advice.actions.back(), request, forecast))
            advice.fall_away.push_back(*f);
    }
    advice.proud = proud_search(instrument, map, request, trials);
    advice.relief = relief_search(instrument, request, forecast, trials);
    advice.wall_seconds = timer.wall_seconds();
    advice.cpu_seconds = timer.cpu_seconds();
    return advice;
}

std::string beyond_setup_text(const ActionAdvice& x) {
    if (!x.beyond_setup) return "";
    // Up that far: the neck or the playing is at fault. Down that far: room to spare, but not a
    // set-up's move either.
    const bool up = x.saddle_change_m > 0.0;
    return std::string(up ? "up" : "down") + ", past the " + mm_text(kSetupSaddleMove) + " a set-up moves: " +
           (up ? "the neck or the playing needs more than a set-up"
               : "the string has that much room to spare, more than a set-up takes");
}

std::string beyond_setup_text(const ReliefAdvice& r) {
    if (!r.beyond_setup) return "";
    return "past the " + mm_text(kSetupReliefMax) +
           " of relief a set-up gives: the neck or the playing needs more than a set-up";
}

std::string advice_json(const Advice& a) {
    using Json = nlohmann::ordered_json;
    const auto number = [](double v) { return std::isfinite(v) ? Json(v * 1e3) : Json(); };
    const auto inches = [](double v) { return std::isfinite(v) ? Json(v / kInch) : Json(); };
    // In turns where the file says what a turn does (+ clockwise), else null.
    const auto turns = [](double move, double per_turn) {
        const double t = screw_turns_for(move, per_turn);
        return std::isfinite(t) ? Json(t) : Json();
    };
    Json actions = Json::array();
    for (const ActionAdvice& x : a.actions)
        actions.push_back(Json{{"string", x.string},
                               {"action12_mm", number(x.current_m)},
                               {"action12_in", inches(x.current_m)},
                               {"predicted_action12_mm", number(x.predicted_m)},
                               {"lowest_clean_action12_mm", number(x.lowest_clean_m)},
                               {"lowest_clean_action12_in", inches(x.lowest_clean_m)},
                               {"measured_fret", x.measured_fret},
                               {"action_at_measured_fret_mm", number(x.current_at_measured_m)},
                               {"lowest_clean_at_measured_fret_mm", number(x.lowest_clean_at_measured_m)},
                               {"saddle_change_mm", number(x.saddle_change_m)},
                               {"saddle_change_in", inches(x.saddle_change_m)},
                               {"saddle_turns", turns(x.saddle_change_m, a.adjusters.saddle_screw_pitch_m)},
                               {"one_step_lower", x.below},
                               {"limiting_fret", x.limiting_fret},
                               {"limiting_against", x.limiting_against < 0 ? Json() : Json(x.limiting_against)},
                               {"beyond_setup", x.beyond_setup},
                               {"beyond_setup_says", beyond_setup_text(x)}});
    Json fall = Json::array();
    for (const FallAwayAdvice& f : a.fall_away)
        fall.push_back(Json{{"string", f.string},
                            {"limiting_fret", f.limiting_fret},
                            {"action12_mm", f.action_now_m * 1e3},
                            {"lower_frets_action12_mm", f.lower_frets_m * 1e3},
                            {"lower_frets_action12_in", f.lower_frets_m / kInch},
                            {"from_fret", f.from_fret},
                            {"depth_mm", f.depth_m * 1e3},
                            {"depth_in", f.depth_m / kInch},
                            {"predicted", true}});
    Json proud = Json::array();
    for (const ProudFret& p : a.proud)
        proud.push_back(Json{{"fret", p.fret},
                             {"lower_by_mm", p.lower_by_m * 1e3},
                             {"lower_by_in", p.lower_by_m / kInch},
                             {"clears", p.cleared},
                             {"worse", p.worse}});
    const ReliefAdvice& r = a.relief;
    return Json{{"attack", a.attack.label},
                {"units", units_name(a.units)},
                {"frets", a.frets},
                {"tolerated", a.tolerated},
                {"step_mm", kActionStep * 1e3},
                {"setup_limits", Json{{"saddle_move_mm", kSetupSaddleMove * 1e3}, {"relief_max_mm", kSetupReliefMax * 1e3}}},
                {"lowest_action", actions},
                {"fall_away", fall},
                {"proud_frets", proud},
                {"relief",
                 Json{{"fret", r.fret},
                      {"relief_mm", number(r.current_m)},
                      {"relief_in", inches(r.current_m)},
                      {"failing_now", r.failing_now},
                      {"best_mm", number(r.best_m)},
                      {"best_in", inches(r.best_m)},
                      {"truss_rod_turns", turns(r.current_m - r.best_m, a.adjusters.truss_rod_turn_m)},
                      {"failing_best", r.failing_best},
                      {"played", r.played},
                      {"beyond_setup", r.beyond_setup},
                      {"beyond_setup_says", beyond_setup_text(r)},
                      {"predicted_clean_from_mm", number(r.predicted_from_m)},
                      {"predicted_clean_to_mm", number(r.predicted_to_m)},
                      {"searched_mm", Json::array({r.searched_from_m * 1e3, r.searched_to_m * 1e3})}}},
                {"maps_played", a.maps},
                {"wall_seconds", a.wall_seconds},
                {"cpu_seconds", a.cpu_seconds}}
        .dump(1);
}

double screw_turns_for(double move_m, double per_turn_m) {
    return per_turn_m > 0.0 && std::isfinite(move_m) ? move_m / per_turn_m : std::numeric_limits<double>::quiet_NaN();
}

std::string turns_text(double turns) {
    if (!std::isfinite(turns)) return "";
    const long eighths = std::lround(std::abs(turns) * 8.0);
    const std::string way = turns < 0.0 ? " anticlockwise" : " clockwise";
    if (eighths == 0) return "less than 1/8 turn";
    const long whole = eighths / 8;
    long part = eighths % 8, below = 8;
    while (part != 0 && part % 2 == 0) {
        part /= 2;
        below /= 2;
    }
    std::string text = whole > 0 ? std::to_string(whole) : "";
    if (part != 0) text += (whole > 0 ? " " : "") + std::to_string(part) + "/" + std::to_string(below);
    return text + (eighths > 8 ? " turns" : " turn") + way;
}

std::string advice_text(const Advice& a) {
    std::ostringstream out;
    const auto shop = [&](double m) { return shop_text(m, a.units); };
    const auto fine = [&](double m) { return shop_text(m, fine_units(a.units)); };
    out << "Advice at the " << a.attack.label << " attack, frets " << a.frets
        << (a.tolerated.empty() ? "" : ", tolerating " + a.tolerated) << " (" << a.maps << " probes played, "
        << std::lround(a.wall_seconds) << " s):\n";
    for (const ActionAdvice& x : a.actions) {
        // Where the file measures elsewhere, the gaps there beside fret 12's.
        const auto there = [&](double m) {
            return x.measured_fret == 12 || !std::isfinite(m)
                       ? std::string()
                       : " (" + shop(m) + " at fret " + std::to_string(x.measured_fret) + ")";
        };
        out << "  string " << x.string << ": action at fret 12 now " << shop(x.current_m)
            << there(x.current_at_measured_m) << "; ";
        if (std::isfinite(x.lowest_clean_m) && x.beyond_setup) {
            out << "the lowest without buzz is " << shop(x.lowest_clean_m) << there(x.lowest_clean_at_measured_m)
                << ", a saddle move of "
                << shop_text(std::abs(x.saddle_change_m), a.units) << " " << beyond_setup_text(x) << " (one step lower, "
                << x.below << ")\n";
        } else if (std::isfinite(x.lowest_clean_m)) {
            out << "the lowest without buzz is " << shop(x.lowest_clean_m) << there(x.lowest_clean_at_measured_m) << ": "
                << (x.saddle_change_m < 0.0 ? "lower" : "raise") << " the saddle "
                << shop_text(std::abs(x.saddle_change_m), a.units);
            if (const std::string t = turns_text(screw_turns_for(x.saddle_change_m, a.adjusters.saddle_screw_pitch_m));
                !t.empty())
                out << " (" << t << " of its height screws)";
            out << " (one step lower, " << x.below << ")\n";
        } else {
            out << "no action up to " << mm_text(kHighestAction) << " is free of buzz"
                << (x.below.empty() ? "" : ": " + x.below) << "\n";
        }
    }
    for (const FallAwayAdvice& f : a.fall_away)
        out << "  string " << f.string << ": the upper frets set that action (fret " << f.limiting_fret
            << "); the frets up to 12 would allow about " << shop(f.lower_frets_m) << ", and a fall-away from fret "
            << f.from_fret << ", about " << fine(f.depth_m) << " deep at the last fret, is predicted to get there "
            << "(from the notes' clean_up_to, not played: --dress --fall-away " << f.from_fret << " works it out)\n";
    if (a.proud.empty())
        out << "  no fret stands proud (none stands " << mm_text(kProudHeight)
            << " above its neighbours' line where a note buzzes against it)\n";
    for (const ProudFret& p : a.proud) {
        out << "  fret " << p.fret << " stands proud: levelling it (" << fine(p.lower_by_m) << " off) clears";
        for (const std::string& n : p.cleared) out << " " << n;
        out << "\n";
    }
    const ReliefAdvice& r = a.relief;
    out << "  relief (gap at fret " << r.fret << ") now " << fine(r.current_m) << " (" << r.failing_now
        << " notes buzz); ";
    if (r.best_m != r.current_m) {
        out << "the least buzz at " << fine(r.best_m) << " (" << r.failing_best << " notes buzz, played)"
            << (r.beyond_setup ? ", " + beyond_setup_text(r) : "");
        // The truss rod tighter (clockwise) takes relief off: the turns are the relief to lose.
        const std::string t = turns_text(screw_turns_for(r.current_m - r.best_m, a.adjusters.truss_rod_turn_m));
        if (!r.beyond_setup && !t.empty()) out << ": the truss rod " << t;
    } else {
        out << "no relief from 0 to " << mm_text(r.searched_to_m) << " is predicted to buzz less";
    }
    if (std::isfinite(r.predicted_from_m))
        out << "; predicted clean from " << fine(r.predicted_from_m) << " to " << fine(r.predicted_to_m);
    out << "\n";
    return out.str();
}

}  // namespace fretbuzz
