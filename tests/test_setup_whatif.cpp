// What-ifs and advice, checked against the physics they stand for: each change moves what it
// should and leaves the rest where it physically is; raising a fret makes the notes below it
// buzz more on every string; more relief quietens the low frets and a flatter neck makes them
// buzz; lowering the action never cleans the map; the advice's lowest action is clean and the
// step below is not; a raised fret is found proud; the relief range holds the clean settings.
// The instrument is the jazz bass simulated coarsely (500 kHz, 0.1 s, 2 mm grid, 3 plucks a
// note): the directions tested are those of the geometry, far larger than what that changes.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <map>

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
    action.action12_m = {{"E", 2.2e-3}};
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
        lower.action12_m.push_back({bass.strings[s].name, StringNeck(bass, s).gap(12) - 0.4e-3});
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
        c.action12_m = {{"G", action}};
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

TEST(SetupAdvice, TheReliefRangeHoldsTheCleanSettings) {
    const Instrument bass = quick_bass(40);
    AdviceRequest request;
    request.attack = straight(bass, "0.6mm").front();
    request.strings = {0};
    const ReliefAdvice r = clean_relief_range(bass, request);
    ASSERT_TRUE(std::isfinite(r.lowest_m));
    EXPECT_LE(r.lowest_m, r.highest_m);
    const auto clean_at = [&](double relief) {
        SetupChange c;
        c.relief_m = relief;
        return map_is_clean(apply_change(bass, c), request, {0});
    };
    EXPECT_TRUE(clean_at(r.lowest_m));
    EXPECT_TRUE(clean_at(r.highest_m));
    std::cout << "clean relief " << r.lowest_m * 1e3 << " to " << r.highest_m * 1e3 << " mm\n";
    if (r.lowest_m > 0.0) {
        EXPECT_FALSE(clean_at(r.lowest_m - kReliefStep));
    }
    if (r.highest_m < r.searched_to_m) {
        EXPECT_FALSE(clean_at(r.highest_m + kReliefStep));
    }
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
}

}  // namespace
}  // namespace fretbuzz
