// The bench's notes and map: the stand-in's closed-form obstacle-free reference is the
// scheme's own free motion; a pluck shown clear of the frets by the amplitude bound touches
// nothing when run; notes nothing can touch report no buzz (the last fret's note, an action
// far above any pluck); a note's verdict from its ensemble; and the single-string built-in's
// map puts the pop against the frets the case-based study of the bass-neck case found.
#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <iostream>
#include <limits>

#include "SetupTestSupport.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/InstrumentFile.hpp"
#include "fretbuzz/run/ResultRecorder.hpp"
#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/setup/BuzzMap.hpp"
#include "fretbuzz/setup/NoteCase.hpp"
#include "fretbuzz/setup/NotePlayer.hpp"
#include "fretbuzz/setup/WhatIf.hpp"

namespace fretbuzz {
namespace {

Instrument quick_bass(std::size_t ensemble = 3) { return testing::quick_bass(ensemble, 0.08); }

Attack pluck_of(const Instrument& instrument, const std::string& label) {
    return parse_attacks(label, instrument.attack).front();
}

// Without an obstacle the string is linear: free_motion_at gives what the scheme computes.
TEST(SetupNotes, TheClosedFormReferenceIsTheSchemesFreeMotion) {
    const Instrument bass = quick_bass();
    const NoteMaker maker(bass, 1);
    for (const char* attack : {"hard", "pop"}) {
        Case c = maker.stand_in(5, pluck_of(bass, attack), {0.004, 5.0, 1.1});
        c.obstacle_height_m.assign(c.mode_count(), -std::numeric_limits<double>::infinity());
        c.point_obstacles.clear();  // the frets, at their exact positions
        ResultRecorder recorder;
        std::vector<RunObserver*> observers{&recorder};
        const RunSummary s = simulate(c, observers);
        const RecordedRun& run = recorder.run();
        const std::vector<double> free =
            free_motion_at(c, c.observation_points_m[0], 1.0 / s.output_rate_hz, run.observation.size());
        double diff = 0.0, norm = 0.0;
        for (std::size_t i = 0; i < free.size(); ++i) {
            diff += (free[i] - run.observation[i]) * (free[i] - run.observation[i]);
            norm += run.observation[i] * run.observation[i];
        }
        EXPECT_LT(std::sqrt(diff / norm), 1e-9) << attack;
    }
}

// The amplitude bound is safe: a pluck it calls clear never touches when run; and it is not
// blind: the hard pluck that buzzes is not called clear.
TEST(SetupNotes, PlucksShownClearTouchNothing) {
    const Instrument bass = quick_bass();
    const NoteMaker maker(bass, 0);
    std::size_t clear = 0;
    for (std::size_t fret : {0u, 5u, 12u, 19u}) {
        for (const char* attack : {"soft", "hard"}) {
            const Case c = maker.stand_in(fret, pluck_of(bass, attack), {});
            if (!never_touches(c)) continue;
            ++clear;
            NoteContacts contacts(maker.fret_positions(fret, false), maker.fret_numbers(fret), false);
            std::vector<RunObserver*> observers{&contacts};
            simulate(c, observers);
            EXPECT_FALSE(contacts.touched()) << "fret " << fret << " " << attack;
        }
    }
    EXPECT_GT(clear, 0u);
    Case loud = maker.stand_in(12, pluck_of(bass, "hard"), {});
    for (double& q : loud.initial_displacement) q *= 4.0;
    EXPECT_FALSE(never_touches(loud));
}

// The note at the last fret has nothing past it but the end of the board and the body: it is
// played, and reports no buzz; so does every note of a string set far above the frets.
TEST(SetupNotes, NotesNothingCanTouchReportNoBuzz) {
    SetupChange high;
    high.action_m = {{"E", 12, 9e-3}};
    const Instrument bass = apply_change(quick_bass(40), high);
    MapRequest request;
    request.attacks = parse_attacks("medium", bass.attack);
    request.strings = {0, 2};
    request.frets = {0, 7, 20};
    const BuzzMapResult map = play_map(bass, request);
    ASSERT_EQ(map.notes.size(), 6u);
    for (const NoteVerdict& v : map.notes) {
        if (v.string != 0 && v.fret != 20) continue;
        EXPECT_EQ(v.status, "ok");
        EXPECT_EQ(v.verdict, "clean");
        EXPECT_EQ(v.plucks, std::min(bass.attack.ensemble, plucks_for_clean()));
        EXPECT_EQ(v.buzz_fraction, 0.0) << v.string_name << " " << v.fret;
        EXPECT_EQ(v.touch_fraction, 0.0) << v.string_name << " " << v.fret;
        EXPECT_TRUE(std::isnan(v.buzz_db));
        EXPECT_EQ(v.buzz_fret, kNoFret);
    }
}

TEST(SetupNotes, AVerdictComesFromItsPlucks) {
    const auto pluck = [](double db, int fret) {
        PluckOutcome p;
        p.simulated = true;
        p.touched = !std::isnan(db);
        p.buzz_db = db;
        p.buzz_fret = p.touched ? fret : kNoFret;
        return p;
    };
    const auto judged = [](std::vector<PluckOutcome> plucks, std::size_t buzzing) {
        AttackJudgement j;
        j.plucks = std::move(plucks);
        j.counted = j.plucks.size();
        j.buzzing = buzzing;
        for (const PluckOutcome& p : j.plucks) j.touching += p.touched ? 1 : 0;
        j.interval = share_interval(j.buzzing, j.counted);
        j.verdict = share_verdict(j.interval);
        return j;
    };
    const double nan = PluckOutcome::nan;
    NoteVerdict v = summarise(judged({pluck(10, 7), pluck(-40, 7), pluck(nan, 0), pluck(5, 8), pluck(0, 8)}, 3), 0.0);
    EXPECT_DOUBLE_EQ(v.buzz_fraction, 0.6);   // 10, 5 and 0 reach 0 dB
    EXPECT_DOUBLE_EQ(v.touch_fraction, 0.8);
    EXPECT_DOUBLE_EQ(v.buzz_db, 0.0);         // median of -inf, -40, 0, 5, 10
    EXPECT_EQ(v.buzz_fret, 8);                // two of the three audible plucks
    EXPECT_EQ(v.verdict, "buzzes");
    EXPECT_LT(v.buzz_fraction_low, 0.6);
    EXPECT_GT(v.buzz_fraction_high, 0.6);
    v = summarise(judged({pluck(nan, 0), pluck(nan, 0), pluck(-40, 3)}, 0), 0.0);
    EXPECT_EQ(v.buzz_fraction, 0.0);
    EXPECT_TRUE(std::isnan(v.buzz_db));      // most plucks touch nothing
    EXPECT_EQ(v.buzz_fret, 3);               // what it touches, though not audibly
    EXPECT_EQ(v.verdict, "marginal");        // three plucks cannot show a note clean
    // The pluck to be heard for the verdict: of a buzzing note its loudest (member 0 is the
    // attack itself, quieter); a pluck not played (behind the fret) keeps its member's place.
    PluckOutcome skipped;
    skipped.error = "not played: behind the fret";
    AttackJudgement buzzing = judged({pluck(-40, 7), skipped, pluck(nan, 0), pluck(12, 8), pluck(5, 8)}, 2);
    buzzing.counted = 4;
    v = summarise(buzzing, 0.0);
    EXPECT_EQ(v.deciding_pluck, 3u);
    // Of a clean note, the loudest one that is not heard.
    std::vector<PluckOutcome> clean(30, pluck(nan, 0));
    clean[4] = pluck(-3, 5);
    clean[9] = pluck(-20, 5);
    v = summarise(judged(clean, 0), 0.0);
    ASSERT_EQ(v.verdict, "clean");
    EXPECT_EQ(v.deciding_pluck, 4u);
    AttackJudgement behind;
    behind.status = "not played: the pluck falls behind fret 20";
    v = summarise(behind, 0.0);
    EXPECT_EQ(v.status, behind.status);
    EXPECT_EQ(v.verdict, "");
}

TEST(SetupNotes, EnsemblesAreDeterministicAndCentredOnTheAttack) {
    const Instrument bass = quick_bass(7);
    const auto a = ensemble(bass.attack, 1, 5, 7), b = ensemble(bass.attack, 1, 5, 7), c = ensemble(bass.attack, 1, 6, 7);
    const auto longer = ensemble(bass.attack, 1, 5, 20);
    ASSERT_EQ(a.size(), 7u);
    EXPECT_EQ(a[0].shift_m, 0.0);
    EXPECT_EQ(a[0].scale, 1.0);
    EXPECT_EQ(a[0].turn_deg, 0.0);
    for (std::size_t m = 1; m < a.size(); ++m) {
        EXPECT_EQ(a[m].shift_m, b[m].shift_m);
        EXPECT_EQ(a[m].scale, b[m].scale);
        EXPECT_EQ(a[m].turn_deg, longer[m].turn_deg);  // a larger ensemble begins with the smaller one
        EXPECT_NE(a[m].shift_m, c[m].shift_m);
        EXPECT_LE(std::abs(a[m].shift_m), bass.attack.position_spread_m);
        EXPECT_LE(std::abs(a[m].scale - 1.0), bass.attack.strength_spread);
        EXPECT_LE(std::abs(a[m].turn_deg), bass.attack.angle_spread_deg);
    }
}

// The held string's modes are kept for the process (a studio or a Python session plays one
// instrument after another), and only they: two instruments that differ in their contact law
// alone play their notes each with its own. Each is heard first on its own (a held string no
// other note of the process has: a grid of its own, and for the second instrument a tension
// one part in 1e16 off, which moves its modes below what a level shows), then after the other.
TEST(SetupNotes, EachInstrumentsNotesKeepTheirOwnContactLaw) {
    const auto bass_with = [](double k, bool own_modes) {
        Instrument bass = quick_bass(1);
        bass.bench.grid_step_m = 2.05e-3;  // no other test's grid
        bass.bench.contact_stiffness = k;
        if (own_modes)
            for (InstrumentString& s : bass.strings) s.tension_n = std::nextafter(s.tension_n, 2.0 * s.tension_n);
        return bass;
    };
    const auto level = [](const Instrument& bass) {
        const NoteMaker maker(bass, 0);
        NotePlayer player(maker, 12, false, listening_settings(bass.bench));
        const Attack hard = pluck_of(bass, "hard");
        const PluckOutcome o = player.play(hard, hard.size, 0, ensemble(bass.attack, 0, 12, 1).front());
        EXPECT_TRUE(o.touched);
        EXPECT_EQ(maker.stopped(12).contact.stiffness, bass.bench.contact_stiffness);
        return o.buzz_db;
    };
    const Instrument stiff = bass_with(1e13, false), soft = bass_with(1e10, false);
    const double stiff_alone = level(stiff);
    const double soft_alone = level(bass_with(1e10, true));
    const double soft_after = level(soft), stiff_after = level(stiff);
    std::cout << "E12 hard: K 1e13 " << stiff_alone << " dB alone, " << stiff_after << " dB after K 1e10; K 1e10 "
              << soft_alone << " dB alone, " << soft_after << " dB after K 1e13\n";
    EXPECT_GT(std::abs(stiff_alone - soft_alone), 3.0);  // the law is heard: the test can tell them apart
    EXPECT_NEAR(soft_after, soft_alone, 0.1);
    EXPECT_NEAR(stiff_after, stiff_alone, 1e-9);
}

// The two models of a stopped note agree where the answer is clear: with fret 9 of the
// bass-neck 0.05 mm proud and a 1 mm pop (straight away from the board), the note of fret 8 buzzes against fret 9 and
// the note of fret 7 touches nothing, with the stand-in and with a finger on the string.
TEST(SetupNotes, TheFingerModelAgreesWithTheStandInWhereTheAnswerIsClear) {
    SetupChange raise;
    raise.frets = {{9, 0.05e-3}};
    Instrument bass = apply_change(load_instrument("bass-neck"), raise);
    bass.bench.sample_rate_hz = 1e6;
    bass.bench.duration_s = 0.1;
    bass.attack.ensemble = 1;
    for (bool finger : {false, true}) {
        MapRequest request;
        request.attacks = parse_attacks("pop", bass.attack);
        request.attacks.front().size = 1e-3;
        request.frets = {7, 8};
        request.finger = finger;
        const BuzzMapResult map = play_map(bass, request);
        ASSERT_EQ(map.notes.size(), 2u);
        EXPECT_EQ(map.notes[0].touch_fraction, 0.0) << (finger ? "finger" : "stand-in");
        EXPECT_EQ(map.notes[1].touch_fraction, 1.0) << (finger ? "finger" : "stand-in");
        EXPECT_EQ(map.notes[1].buzz_fret, 9) << (finger ? "finger" : "stand-in");
    }
}

// The case-based set-up study of the bass-neck case (`fretbuzz setup bass-neck` of an earlier
// version, which rewrote the case file for each fret and ran it as a sweep, computed with the
// build of main at 6bc2dd5): a 2 mm pop, one pluck per note, 4 MHz, 0.5 s. The bench plays
// the same notes from the bass-neck instrument, with the string's own modes at each stopped
// length as that study did (stopped_modes = "pinned"): the pop meets the same fret on every
// note (where the largest impulse goes; the study's level was a waveform difference, which
// the bench no longer uses), and the last fret's note, which the study could not play,
// touches nothing.
TEST(SetupMap, TheSingleStringBuiltInPutsThePopAgainstTheCaseBasedStudysFrets) {
    const std::vector<int> before = {3, 2, 3, 4, 5, 6, 7, 9, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 20, 20};
    Instrument bass = load_instrument("bass-neck");
    bass.attack.ensemble = 1;
    MapRequest request;
    request.attacks = parse_attacks("pop", bass.attack);
    request.clean_up_to = false;
    const BuzzMapResult map = play_map(bass, request);
    ASSERT_EQ(map.notes.size(), 21u);
    for (std::size_t fret = 0; fret < before.size(); ++fret) {
        const NoteVerdict& v = map.notes[fret];
        ASSERT_EQ(v.fret, fret);
        EXPECT_EQ(v.buzz_fret, before[fret]) << "fret " << fret;
        EXPECT_GT(v.buzz_db, 0.0) << "fret " << fret;  // a pop slapping the frets is heard
    }
    EXPECT_EQ(map.notes[20].touch_fraction, 0.0);
}

}  // namespace
}  // namespace fretbuzz
