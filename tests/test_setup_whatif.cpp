// What-ifs and advice, checked against the physics they stand for: each change moves what it
// should and leaves the rest where it physically is; raising a fret makes the notes below it
// buzz more on every string; more relief quietens the low frets and a flatter neck makes them
// buzz; lowering the action never cleans the map; the advice's lowest action is clean and the
// step below is not, given as a saddle move in the file's units; a raised fret is found proud, and
// a level board has none; the best relief buzzes no more than today; --frets limits the advice.
// The instrument is the jazz bass simulated coarsely (500 kHz, 0.1 s, 2 mm grid, 3 plucks a
// note): the directions tested are those of the geometry, far larger than what that changes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <regex>

#include "SetupTestSupport.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/InstrumentFile.hpp"
#include "fretbuzz/setup/Advice.hpp"
#include "fretbuzz/setup/BuzzMap.hpp"
#include "fretbuzz/setup/MapFiles.hpp"
#include "fretbuzz/setup/StringNeck.hpp"
#include "fretbuzz/setup/WhatIf.hpp"

namespace fretbuzz {
namespace {

Instrument quick_bass(std::size_t ensemble = 3) { return testing::quick_bass(ensemble, 0.1); }

// The directions these tests check are the geometry's: each attack here pulls the string
// straight away from the board (a pop's gesture) by the amplitude its label names, so that
// it swings as far toward the frets: soft 0.5 mm, medium 1 mm, hard 1.5 mm, or "0.8mm".
std::vector<Attack> straight(const Instrument& instrument, const std::string& labels) {
    std::vector<Attack> attacks = parse_attacks(labels, instrument.attack);
    for (Attack& a : attacks) {
        const double size = a.label == "soft" ? 0.5e-3 : a.label == "medium" ? 1e-3 : a.label == "hard" ? 1.5e-3 : a.size;
        a.gesture = Gesture::pop;
        a.where.angle_deg = -90.0;
        a.size = size;
    }
    return attacks;
}

std::vector<NoteVerdict> play(const Instrument& instrument, const std::string& attacks, std::vector<std::size_t> frets,
                              std::vector<std::size_t> strings = {}) {
    MapRequest r;
    r.attacks = straight(instrument, attacks);
    r.clean_up_to = false;
    r.frets = std::move(frets);
    r.strings = std::move(strings);
    return play_map(instrument, r).notes;
}

// The share of plucks that buzz audibly, summed over notes, per attack.
std::map<std::string, double> buzz(const std::vector<NoteVerdict>& notes) {
    std::map<std::string, double> total;
    for (const NoteVerdict& v : notes) total[v.strength] += v.buzz_fraction;
    return total;
}

TEST(SetupWhatIf, EachChangeMovesWhatItShouldAndNothingElse) {
    const Instrument bass = load_instrument("jazz-bass");
    const StringNeck before(bass, 0);
    SetupChange relief;
    relief.relief_m = 0.8e-3;
    const StringNeck looser(apply_change(bass, relief), 0);
    EXPECT_NEAR(looser.relief_gap(8), 0.8e-3, 1e-12);
    EXPECT_NEAR(looser.nut_height(), before.nut_height(), 1e-15);        // the nut and saddle stay
    EXPECT_NEAR(looser.saddle_height(), before.saddle_height(), 1e-15);
    EXPECT_GT(looser.gap(12), before.gap(12));                            // the frets sink under the string

    SetupChange action;
    action.action_m = {{"E", 12, 2.2e-3}};
    const StringNeck lower(apply_change(bass, action), 0);
    EXPECT_NEAR(lower.gap(12), 2.2e-3, 1e-15);
    EXPECT_NEAR(lower.nut_height(), before.nut_height(), 1e-15);
    EXPECT_NEAR(StringNeck(apply_change(bass, action), 1).gap(12), StringNeck(bass, 1).gap(12), 1e-15);

    SetupChange nut;
    nut.nut_m = {{"E", 0.5e-3}};
    const StringNeck filed(apply_change(bass, nut), 0);
    EXPECT_NEAR(filed.gap(1), 0.5e-3, 1e-15);
    EXPECT_NEAR(filed.saddle_height(), before.saddle_height(), 1e-15);

    SetupChange saddle;
    saddle.saddle_m = {{"E", before.saddle_height() - 0.3e-3}};
    const StringNeck sunk(apply_change(bass, saddle), 0);
    EXPECT_NEAR(sunk.saddle_height(), before.saddle_height() - 0.3e-3, 1e-15);
    EXPECT_NEAR(sunk.nut_height(), before.nut_height(), 1e-15);

    SetupChange raise;
    raise.frets = {{7, 0.3e-3}};
    const Instrument raised = apply_change(bass, raise);
    for (std::size_t s = 0; s < 4; ++s) {
        const StringNeck a(bass, s), b(raised, s);
        EXPECT_NEAR(b.fret_top(7) - a.fret_top(7), 0.3e-3, 1e-15);
        EXPECT_NEAR(b.fret_top(8), a.fret_top(8), 1e-15);
        EXPECT_NEAR(b.saddle_height(), a.saddle_height(), 1e-15);
    }
    // Levelling dresses it down to its neighbours' line under the string that needs least.
    SetupChange level;
    level.frets = {{7, std::nullopt}};
    const Instrument levelled = apply_change(raised, level);
    double worst = -1.0;
    for (std::size_t s = 0; s < 4; ++s) {
        const StringNeck n(levelled, s);
        const double line = n.fret_top(6) + (n.fret_top(8) - n.fret_top(6)) * (n.fret_x(7) - n.fret_x(6)) /
                                                (n.fret_x(8) - n.fret_x(6));
        EXPECT_LE(n.fret_top(7), line + 1e-15);
        worst = std::max(worst, n.fret_top(7) - line);
    }
    EXPECT_NEAR(worst, 0.0, 1e-15);
    // A fret that is not proud cannot be levelled; a fret that does not exist is named.
    EXPECT_THROW(apply_change(bass, level), InputError);
    SetupChange missing;
    missing.frets = {{21, 0.1e-3}};
    try {
        apply_change(bass, missing);
        ADD_FAILURE() << "fret 21 accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("frets 1 to 20"), std::string::npos) << e.what();
    }
}

// A fret 0.3 mm proud stands in the way of the notes just below it: on every string, each of
// the notes at frets k-3 to k-1 buzzes in more of its plucks (clean before, at medium).
TEST(SetupWhatIf, RaisingAFretMakesTheNotesBelowItBuzzMoreOnEveryString) {
    const Instrument bass = quick_bass();
    SetupChange raise;
    raise.frets = {{7, 0.3e-3}};
    const std::vector<NoteVerdict> before = play(bass, "medium", {4, 5, 6});
    const std::vector<NoteVerdict> after = play(apply_change(bass, raise), "medium", {4, 5, 6});
    ASSERT_EQ(before.size(), 12u);
    for (std::size_t i = 0; i < before.size(); ++i) {
        EXPECT_GT(after[i].buzz_fraction, before[i].buzz_fraction) << after[i].string_name << " " << after[i].fret;
        EXPECT_EQ(after[i].buzz_fret, 7) << after[i].string_name << " " << after[i].fret;
    }
}

// Relief lifts the middle of the string off the frets: the low frets' notes buzz less with
// more of it and more with a flatter neck (the nut and saddle staying put).
TEST(SetupWhatIf, MoreReliefQuietensTheLowFretsAndAFlatterNeckMakesThemBuzz) {
    const Instrument bass = quick_bass();
    std::vector<double> hard, medium;
    for (double relief : {0.2e-3, 0.54e-3, 0.9e-3}) {
        SetupChange c;
        c.relief_m = relief;
        const auto score = buzz(play(apply_change(bass, c), "medium,hard", {1, 2, 3, 4, 5}));
        medium.push_back(score.at("medium"));
        hard.push_back(score.at("hard"));
    }
    EXPECT_GT(medium[0], medium[1]);  // flatter: the medium pluck starts to buzz
    EXPECT_GT(hard[0], hard[1]);
    EXPECT_GT(hard[1], hard[2]);      // more relief: the hard one buzzes less
    EXPECT_GE(medium[1], medium[2]);
}

// Lowering every string's action over fret 12 by 0.4 mm brings the string closer to every
// fret past the nut: the map is never cleaner, at any attack.
TEST(SetupWhatIf, LoweringTheActionNeverCleansTheMap) {
    const Instrument bass = quick_bass();
    SetupChange lower;
    for (std::size_t s = 0; s < bass.strings.size(); ++s)
        lower.action_m.push_back({bass.strings[s].name, 12, StringNeck(bass, s).gap(12) - 0.4e-3});
    std::vector<std::size_t> frets;
    for (std::size_t k = 0; k <= 20; k += 2) frets.push_back(k);
    const auto before = buzz(play(bass, "soft,medium,hard", frets));
    const auto after = buzz(play(apply_change(bass, lower), "soft,medium,hard", frets));
    for (const auto& [attack, score] : before) EXPECT_GE(after.at(attack), score) << attack;
    EXPECT_GT(after.at("medium") + after.at("hard"), before.at("medium") + before.at("hard"));
}

// The lowest clean action: clean when played, and the 0.05 mm step below is not (or cannot
// be set: the open string would lie on a fret).
TEST(SetupAdvice, TheLowestActionIsCleanAndTheStepBelowIsNot) {
    const Instrument bass = quick_bass(40);
    AdviceRequest request;
    request.attack = straight(bass, "medium").front();
    const ActionAdvice a = lowest_clean_action(bass, 3, request);
    ASSERT_TRUE(std::isfinite(a.lowest_clean_m)) << a.below;
    EXPECT_NEAR(std::remainder(a.lowest_clean_m, kActionStep), 0.0, 1e-12);
    const auto at = [&](double action) {
        SetupChange c;
        c.action_m = {{"G", 12, action}};
        return apply_change(bass, c);
    };
    for (const NoteVerdict& v : play(at(a.lowest_clean_m), "medium", {}, {3}))
        EXPECT_EQ(v.verdict, "clean") << "fret " << v.fret;
    std::size_t below = 0;
    try {
        for (const NoteVerdict& v : play(at(a.lowest_clean_m - kActionStep), "medium", {}, {3})) below += v.verdict != "clean";
        EXPECT_GT(below, 0u) << a.below;
    } catch (const InputError& e) {
        EXPECT_NE(a.below.find("would lie on a fret"), std::string::npos) << a.below;  // cannot be set
    }
}

// A fret raised 0.08 mm above its neighbours makes the notes below it buzz against it; the
// advice finds it proud, its lowering by at most 0.1 mm clearing them (at a 0.7 mm pluck,
// which the level neck plays clean).
TEST(SetupAdvice, ARaisedFretIsFoundProud) {
    SetupChange raise;
    raise.frets = {{9, 0.08e-3}};
    const Instrument bass = apply_change(quick_bass(40), raise);
    AdviceRequest request;
    request.attack = straight(bass, "0.7mm").front();
    request.strings = {3};
    const std::vector<NoteVerdict> map = play(bass, "0.7mm", {6, 7, 8, 9}, {3});
    const std::vector<ProudFret> proud = proud_frets(bass, map, request);
    ASSERT_FALSE(proud.empty());
    EXPECT_EQ(proud.front().fret, 9u);
    EXPECT_LE(proud.front().lower_by_m, 0.1e-3 + 1e-15);
    EXPECT_FALSE(proud.front().cleared.empty());
    EXPECT_TRUE(proud.front().worse.empty());  // levelling it harms no note
}

// The relief the advice recommends buzzes on no more notes than today's (it is played), and
// the number it gives for it is what a map at that relief finds.
TEST(SetupAdvice, TheBestReliefBuzzesNoMoreThanToday) {
    const Instrument bass = quick_bass(40);
    AdviceRequest request;
    request.attack = straight(bass, "0.8mm").front();
    request.strings = {0};
    MapRequest r;
    r.attacks = {request.attack};
    r.strings = {0};
    const std::vector<NoteVerdict> map = play_map(bass, r).notes;  // with clean_up_to: it places the search
    const ReliefAdvice relief = best_relief(bass, map, request);
    ASSERT_TRUE(std::isfinite(relief.best_m));
    EXPECT_TRUE(relief.played);
    EXPECT_LE(relief.failing_best, relief.failing_now);
    std::size_t failing = 0;
    for (const NoteVerdict& v : map) failing += v.verdict != "clean";
    EXPECT_EQ(relief.failing_now, failing);
    SetupChange c;
    c.relief_m = relief.best_m;
    std::size_t there = 0;
    for (const NoteVerdict& v : play(apply_change(bass, c), "0.8mm", {}, {0})) there += v.verdict != "clean";
    EXPECT_EQ(there, relief.failing_best);
    std::cout << "relief " << relief.current_m * 1e3 << " mm: " << relief.failing_now << " notes buzz; at "
              << relief.best_m * 1e3 << " mm: " << relief.failing_best << "\n";
}

// A level board has no proud fret, whatever strings are played: levelling a fret in line
// with its neighbours is no fret work (the old search called fret 14 proud when only the G
// string was played). On a level Les Paul board neither (the old search named fret 22).
TEST(SetupAdvice, ALevelBoardHasNoProudFret) {
    const Instrument bass = quick_bass(20);
    for (const std::vector<std::size_t>& strings : std::vector<std::vector<std::size_t>>{{3}, {0}, {0, 1, 2, 3}}) {
        AdviceRequest request;
        request.attack = straight(bass, "1.2mm").front();
        request.strings = strings;
        const std::vector<NoteVerdict> map = play(bass, "1.2mm", {}, strings);
        ASSERT_TRUE(std::any_of(map.begin(), map.end(), [](const NoteVerdict& v) { return v.verdict == "buzzes"; }));
        EXPECT_TRUE(proud_frets(bass, map, request).empty()) << strings.size() << " strings";
    }
    Instrument les_paul = parse_instrument(R"(name = "les-paul"
[neck]
scale = "24.75 in"
frets = 22
fret_height = "0.043 in"
radius = "12 in"
nut_width = "1 11/16 in"
bridge_spacing = "2 1/16 in"
body_depth = "6 mm"
[neck.relief]
gap = "0.010 in"
fret = 8
[strings]
set = "daddario-exl110"
[[string]]
name = "E"
pitch = "E2"
nut = "0.022 in"
action = "4/64 in"
action_fret = 12
[[string]]
name = "A"
pitch = "A2"
nut = "0.020 in"
action = "4/64 in"
action_fret = 12
[[string]]
name = "D"
pitch = "D3"
nut = "0.018 in"
action = "4/64 in"
action_fret = 12
[[string]]
name = "G"
pitch = "G3"
nut = "0.016 in"
action = "3.5/64 in"
action_fret = 12
[[string]]
name = "B"
pitch = "B3"
nut = "0.014 in"
action = "3.5/64 in"
action_fret = 12
[[string]]
name = "e"
pitch = "E4"
nut = "0.012 in"
action = "3.5/64 in"
action_fret = 12
)",
                                           "les-paul.toml", DataSource::builtin());
    les_paul.bench = bass.bench;
    les_paul.attack.ensemble = 20;
    EXPECT_EQ(les_paul.units, ShopUnits::sixty_fourths);
    for (std::size_t f = 1; f <= 22; ++f) EXPECT_LT(proud_height(les_paul, f), kProudHeight) << "fret " << f;
    AdviceRequest request;
    request.attack = straight(les_paul, "1mm").front();
    request.strings = {5};
    const std::vector<NoteVerdict> map = play(les_paul, "1mm", {18, 19, 20, 21, 22}, {5});
    EXPECT_TRUE(proud_frets(les_paul, map, request).empty());
}

// --frets 0-12: the advice answers for those notes alone, and names no note above fret 12.
TEST(SetupAdvice, TheAdviceAnswersForTheFretsAsked) {
    const Instrument bass = quick_bass(40);
    AdviceRequest request;
    request.attack = straight(bass, "1mm").front();
    request.strings = {3};
    for (std::size_t k = 0; k <= 12; ++k) request.frets.push_back(k);
    MapRequest r;
    r.attacks = {request.attack};
    r.strings = {3};
    r.frets = request.frets;
    const Advice advice = advise(bass, play_map(bass, r).notes, request);
    ASSERT_EQ(advice.actions.size(), 1u);
    EXPECT_LE(advice.actions.front().limiting_fret, 12u) << advice.actions.front().below;
    const std::string text = advice_text(advice);
    std::smatch m;
    for (auto at = text.cbegin(); std::regex_search(at, text.cend(), m, std::regex(R"(\bG (?:fret )?(\d+))")); at = m.suffix().first)
        EXPECT_LE(std::stoi(m[1]), 12) << text;
    EXPECT_NE(text.find("frets 0-12"), std::string::npos) << text;
    // Notes above fret 12 tolerated: the same answer as --frets 0-12 (the same plucks).
    AdviceRequest tolerant = request;
    tolerant.frets.clear();
    tolerant.tolerate = parse_tolerance("above=12", bass.neck.fret_count);
    EXPECT_EQ(advice_frets(bass, tolerant), request.frets);
    EXPECT_THROW(parse_tolerance("above=21", 20), InputError);
    EXPECT_THROW(parse_tolerance("quiet", 20), InputError);
}

// The lowest action is given as the saddle's move from today, in the instrument file's units.
TEST(SetupAdvice, TheActionIsGivenAsASaddleMoveInTheFilesUnits) {
    Instrument bass = quick_bass(40);
    bass.strings[3].action_fret = 17;  // as a file that measures where Fender does
    AdviceRequest request;
    request.attack = straight(bass, "1mm").front();
    const ActionAdvice a = lowest_clean_action(bass, 3, request);
    ASSERT_TRUE(std::isfinite(a.lowest_clean_m)) << a.below;
    SetupChange c;
    c.action_m = {{"G", 12, a.lowest_clean_m}};
    EXPECT_NEAR(a.saddle_change_m,
                StringNeck(apply_change(bass, c), 3).saddle_height() - StringNeck(bass, 3).saddle_height(), 1e-12);
    // The answer said at fret 17 too: the same saddle, its gap there.
    EXPECT_EQ(a.measured_fret, 17u);
    EXPECT_NEAR(a.current_at_measured_m, StringNeck(bass, 3).gap(17), 1e-15);
    EXPECT_NEAR(a.lowest_clean_at_measured_m, StringNeck(apply_change(bass, c), 3).gap(17), 1e-12);
    EXPECT_NE(a.lowest_clean_at_measured_m, a.lowest_clean_m);
    // Nut pinned: the saddle moves twice what the gap over fret 12 (half way) does.
    EXPECT_NEAR(a.saddle_change_m, 2.0 * (a.lowest_clean_m - a.current_m), 0.02e-3);
    Advice advice;
    advice.attack = request.attack;
    advice.actions = {a};
    advice.units = ShopUnits::sixty_fourths;
    const std::string text = advice_text(advice);
    EXPECT_NE(text.find("/64 in ("), std::string::npos) << text;
    EXPECT_NE(text.find(" at fret 17)"), std::string::npos) << text;
    EXPECT_NE(text.find(" mm)"), std::string::npos) << text;
    advice.units = ShopUnits::thousandths;
    EXPECT_NE(advice_text(advice).find(" in ("), std::string::npos);
}

// Set-up practice when the player says nothing: marginal notes pass, and a bass's notes above
// fret 15 are not asked to; a guitar's player may use every fret. "none" asks every note.
TEST(SetupAdvice, SetUpPracticeToleratesMarginalNotesAndABasssTopFrets) {
    const Instrument bass = load_instrument("jazz-bass");
    const AdviceTolerance b = tolerance_for(bass, "");
    EXPECT_TRUE(b.marginal);
    ASSERT_TRUE(b.above_fret.has_value());
    EXPECT_EQ(*b.above_fret, 15u);
    EXPECT_TRUE(b.ignores(16));
    EXPECT_FALSE(b.ignores(15));
    EXPECT_NE(b.text().find("as set-ups do"), std::string::npos) << b.text();
    AdviceRequest request;
    request.tolerate = b;
    const std::vector<std::size_t> frets = advice_frets(bass, request);
    ASSERT_FALSE(frets.empty());
    EXPECT_EQ(frets.back(), 15u);
    const Instrument guitar = load_instrument("electric-guitar");
    const AdviceTolerance g = tolerance_for(guitar, "");
    EXPECT_TRUE(g.marginal);
    EXPECT_FALSE(g.above_fret.has_value());
    const AdviceTolerance strict = tolerance_for(bass, "none");
    EXPECT_FALSE(strict.marginal);
    EXPECT_FALSE(strict.above_fret.has_value());
    EXPECT_EQ(strict.text(), "");
    // Asked for, it is what was asked: no "as set-ups do".
    EXPECT_EQ(tolerance_for(bass, "above=17").text(), "notes above fret 17");
}

// A saddle raised more than a set-up moves (1 mm) is flagged, not recommended: the G string's
// action dropped 0.6 mm under where it plays clean asks the saddle up about 1.2 mm.
TEST(SetupAdvice, AMoveBeyondASetUpIsFlaggedNotRecommended) {
    const Instrument bass = quick_bass(40);
    AdviceRequest request;
    request.attack = straight(bass, "1mm").front();
    const ActionAdvice today = lowest_clean_action(bass, 3, request);
    ASSERT_TRUE(std::isfinite(today.lowest_clean_m)) << today.below;
    EXPECT_EQ(today.beyond_setup, std::abs(today.saddle_change_m) > kSetupSaddleMove) << today.saddle_change_m;
    SetupChange low;
    low.action_m = {{"G", 12, today.lowest_clean_m - 0.6e-3}};
    const ActionAdvice a = lowest_clean_action(apply_change(bass, low), 3, request);
    ASSERT_TRUE(std::isfinite(a.lowest_clean_m)) << a.below;
    EXPECT_GT(a.saddle_change_m, kSetupSaddleMove);
    EXPECT_TRUE(a.beyond_setup);
    Advice advice;
    advice.attack = request.attack;
    advice.actions = {a};
    advice.relief.current_m = 0.3e-3;
    advice.relief.best_m = 0.7e-3;  // past the 0.5 mm a set-up gives
    advice.relief.beyond_setup = true;
    const std::string text = advice_text(advice);
    EXPECT_NE(text.find("the neck or the playing needs more than a set-up"), std::string::npos) << text;
    EXPECT_EQ(text.find("raise the saddle"), std::string::npos) << text;
    EXPECT_NE(text.find("past the 0.5 mm of relief"), std::string::npos) << text;
    EXPECT_NE(advice_json(advice).find("\"beyond_setup\": true"), std::string::npos);
    // The pages print the library's words, the same as the text's.
    EXPECT_NE(advice_json(advice).find("\"beyond_setup_says\": \"up, past the 1 mm a set-up moves"), std::string::npos);
    // Lowered that far, the string has room to spare: not a set-up's move, and not a fault of the neck.
    ActionAdvice down = a;
    down.saddle_change_m = -a.saddle_change_m;
    advice.actions = {down};
    advice.relief = ReliefAdvice{};
    const std::string lowered = advice_text(advice);
    EXPECT_NE(lowered.find("down, past the 1 mm a set-up moves: the string has that much room to spare"), std::string::npos)
        << lowered;
    EXPECT_EQ(lowered.find("lower the saddle"), std::string::npos) << lowered;
    EXPECT_EQ(lowered.find("needs more than a set-up"), std::string::npos) << lowered;
}

TEST(SetupCompare, NotesAreMarkedByHowTheyChanged) {
    const auto note = [](std::size_t fret, double fraction, double db, int buzz_fret) {
        NoteVerdict v;
        v.string_name = "E";
        v.fret = fret;
        v.strength = "hard";
        v.plucks = 5;
        v.buzz_fraction = fraction;
        v.buzz_db = db;
        v.buzz_fret = buzz_fret;
        return v;
    };
    const std::vector<NoteVerdict> before = {note(1, 0.2, -10, 2), note(2, 0.6, -10, 3), note(3, 1, -10, 4),
                                             note(4, 1, -10, 5), note(5, 0, NoteVerdict::nan, kNoFret)};
    const std::vector<NoteVerdict> now = {note(1, 0.6, -10, 2), note(2, 0.2, -10, 3), note(3, 1, -5, 4),
                                          note(4, 1, -11, 6), note(5, 0, NoteVerdict::nan, kNoFret), note(6, 0, 0, 0)};
    const std::vector<NoteChange> c = compare_maps(now, before);
    ASSERT_EQ(c.size(), 6u);
    EXPECT_EQ(c[0].change, "worse");
    EXPECT_EQ(c[1].change, "better");
    EXPECT_EQ(c[2].change, "worse");   // as many plucks, 5 dB louder
    EXPECT_EQ(c[3].change, "moved");   // as many, against another fret
    EXPECT_EQ(c[4].change, "same");
    EXPECT_EQ(c[5].change, "new");
    // Each says the rule that decided it, so a page never explains a change by plucks that did not change.
    EXPECT_EQ(c[0].reason, "plucks");
    EXPECT_EQ(c[2].reason, "loudness");
    EXPECT_EQ(c[3].reason, "fret");
    EXPECT_EQ(c[4].reason, "");
    // A clean note whose margin shrank: worse with 0 of its plucks buzzing before and after.
    NoteVerdict was = note(7, 0, NoteVerdict::nan, kNoFret), is = was;
    was.verdict = is.verdict = "clean";
    was.clean_up_to = 1.8;
    is.clean_up_to = 1.2;
    const std::vector<NoteChange> margin = compare_maps(std::vector<NoteVerdict>{is}, std::vector<NoteVerdict>{was});
    EXPECT_EQ(margin[0].change, "worse");
    EXPECT_EQ(margin[0].reason, "margin");
    is.verdict = "buzzes";
    EXPECT_EQ(compare_maps(std::vector<NoteVerdict>{is}, std::vector<NoteVerdict>{was})[0].reason, "verdict");
}

}  // namespace
}  // namespace fretbuzz
