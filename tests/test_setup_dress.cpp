// The virtual fret dress finds real faults and invents none: a neck with three frets raised
// by 0.05 to 0.1 mm is dressed at those frets, by no more than 1.2 times what they were
// raised, and every note then passes; a level neck that plays clean needs nothing; a
// fall-away takes the frets past where it starts off along a line. The instrument is
// the jazz bass simulated coarsely (SetupTestSupport.hpp), its G string plucked 0.7 mm
// straight from the board: the level neck plays it clean up to fret 15.
#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <iostream>
#include <map>

#include "SetupTestSupport.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/setup/FretDress.hpp"
#include "fretbuzz/setup/WhatIf.hpp"

namespace fretbuzz {
namespace {

Attack pulled(const Instrument& instrument, const std::string& label) {
    Attack a = parse_attacks(label, instrument.attack).front();
    a.gesture = Gesture::pop;
    a.where.angle_deg = -90.0;
    return a;
}

// The G string's notes up to fret 15 (above, the level neck is marginal at this attack).
DressRequest g_string(const Instrument& instrument) {
    DressRequest r;
    r.play.attack = pulled(instrument, "0.7mm");
    r.play.strings = {3};
    for (std::size_t k = 0; k <= 15; ++k) r.play.frets.push_back(k);
    return r;
}

std::vector<NoteVerdict> map_of(const Instrument& instrument, const DressRequest& r) {
    MapRequest m;
    m.attacks = {r.play.attack};
    m.strings = r.play.strings;
    m.frets = r.play.frets;
    return play_map(instrument, m).notes;
}

TEST(SetupDress, ALevelNeckThatPlaysCleanNeedsNothing) {
    const Instrument bass = testing::quick_bass(40, 0.1);
    const DressRequest request = g_string(bass);
    const std::vector<NoteVerdict> before = map_of(bass, request);
    for (const NoteVerdict& v : before) ASSERT_EQ(v.verdict, "clean") << "fret " << v.fret;
    const DressResult d = dress_frets(bass, before, request);
    for (std::size_t f = 1; f < d.remove_m.size(); ++f) EXPECT_EQ(d.remove_m[f], 0.0) << "fret " << f;
    EXPECT_TRUE(d.clean);
    EXPECT_TRUE(d.unresolved.empty());
    EXPECT_NE(dress_text(d).find("nothing to take off"), std::string::npos) << dress_text(d);
}

TEST(SetupDress, ThreeRaisedFretsAreDressedAtThoseFrets) {
    const std::map<std::size_t, double> raised{{9, 0.08e-3}, {12, 0.1e-3}, {15, 0.05e-3}};
    SetupChange raise;
    for (const auto& [fret, by] : raised) raise.frets.push_back({fret, by});
    const Instrument bass = apply_change(testing::quick_bass(40, 0.1), raise);
    const DressRequest request = g_string(bass);
    const std::vector<NoteVerdict> before = map_of(bass, request);
    std::map<int, int> against;
    for (const NoteVerdict& v : before)
        if (v.verdict != "clean") ++against[v.buzz_fret];
    for (const auto& [fret, by] : raised) EXPECT_GT(against[static_cast<int>(fret)], 0) << "nothing buzzes on fret " << fret;
    const DressResult d = dress_frets(bass, before, request);
    std::cout << dress_text(d);
    for (std::size_t f = 1; f < d.remove_m.size(); ++f) {
        const auto r = raised.find(f);
        if (r == raised.end()) {
            EXPECT_EQ(d.remove_m[f], 0.0) << "fret " << f << " was never raised";
        } else {
            EXPECT_GT(d.remove_m[f], 0.0) << "fret " << f;
            EXPECT_LE(d.remove_m[f], 1.2 * r->second + 1e-12) << "fret " << f;
        }
    }
    EXPECT_TRUE(d.clean) << dress_text(d);
    for (const NoteVerdict& v : d.after) EXPECT_EQ(v.verdict, "clean") << "fret " << v.fret;
    const std::string csv = dress_csv(d);
    EXPECT_EQ(csv.substr(0, csv.find('\n')), "fret,remove_mm,remove_thou");
}

// A fret a little proud (0.008 mm, under what a file takes) comes down by a file's cut,
// 0.02 mm, not by the 0.01 mm the notes alone would ask: no cut a fret file cannot make.
TEST(SetupDress, NoCutIsSmallerThanAFretFileTakes) {
    SetupChange raise;
    raise.frets = {{9, 0.008e-3}};
    const Instrument bass = apply_change(testing::quick_bass(40, 0.1), raise);
    DressRequest request = g_string(bass);
    request.play.attack = pulled(bass, "0.95mm");
    request.play.frets = {5, 6, 7, 8};  // the notes below it, which buzz against it
    const std::vector<NoteVerdict> before = map_of(bass, request);
    ASSERT_TRUE(std::any_of(before.begin(), before.end(), [](const NoteVerdict& v) { return v.verdict != "clean"; }));
    const DressResult d = dress_frets(bass, before, request);
    std::cout << dress_text(d);
    std::size_t cut = 0;
    for (std::size_t f = 1; f < d.remove_m.size(); ++f)
        if (d.remove_m[f] > 0.0) {
            ++cut;
            EXPECT_GE(d.remove_m[f], 0.02e-3 - 1e-15) << "fret " << f;  // a file's cut
        }
    EXPECT_GT(cut, 0u) << dress_text(d);
}

// A fall-away takes nothing off up to its fret and off the rest along a line to the last.
TEST(SetupDress, AFallAwayIsAStraightLine) {
    const Instrument bass = testing::quick_bass(20, 0.1);
    DressRequest request = g_string(bass);
    request.play.attack = pulled(bass, "0.8mm");
    request.play.frets.clear();  // every note: the upper ones buzz against the frets past 16
    request.play.tolerate.marginal = true;
    request.fall_away_from = 16;
    const DressResult d = dress_frets(bass, map_of(bass, request), request);
    std::cout << dress_text(d);
    ASSERT_EQ(d.fall_away_from, 16u) << dress_text(d);
    ASSERT_GT(d.fall_away_m, 0.0);
    const StringNeck neck(bass, 3);
    for (std::size_t f = 17; f <= 20; ++f) {
        const double line = d.fall_away_m * (neck.fret_x(f) - neck.fret_x(16)) / (neck.fret_x(20) - neck.fret_x(16));
        EXPECT_GE(d.remove_m[f], line - 1e-12) << "fret " << f;
    }
    EXPECT_THROW(
        {
            DressRequest bad = request;
            bad.fall_away_from = 19;
            check_dress_request(bass, bad);
        },
        InputError);
}

}  // namespace
}  // namespace fretbuzz
