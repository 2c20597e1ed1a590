// The shop's units and moves in the set-up bench's what-ifs: a length takes mm, in, a
// fraction of an inch in any denominator or thou, and a bare number is in the instrument
// file's own units (an inch file's --relief 0.012 is 0.012 in, not 0.012 mm); the action is
// set at any fret (--action 17:E=3/32in), --action12 being fret 12's shorthand through the same
// path; relative moves (--saddle-change, --relief-change, --nut-change) compose with the
// file's values; an end set twice is refused; "action17" in a file points to action and
// action_fret.
#include <gtest/gtest.h>

#include <string>

#include "SetupTestSupport.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/BuiltinFiles.hpp"
#include "fretbuzz/input/InstrumentFile.hpp"
#include "fretbuzz/input/InstrumentUnits.hpp"
#include "fretbuzz/setup/Advice.hpp"
#include "fretbuzz/setup/StringNeck.hpp"
#include "fretbuzz/setup/WhatIf.hpp"

namespace fretbuzz {
namespace {

constexpr double kIn = 0.0254;

const std::string& bass_text() {
    static const std::string text(*find_builtin_file("instruments/jazz-bass.toml"));
    return text;
}

// The jazz bass as a shop that measures in inches enters it: its first string's nut and
// action in inches (an action gauge's 64ths).
Instrument inch_bass() {
    std::string text = testing::replaced(bass_text(), "nut = \"0.75 mm\"", "nut = \"0.030 in\"");
    text = testing::replaced(text, "action12 = \"2.7 mm\"", "action12 = \"7/64 in\"");
    return parse_instrument(text, "inch-bass.toml", DataSource::builtin());
}

const Instrument& jazz_bass() {
    static const Instrument bass = load_instrument("jazz-bass");
    return bass;
}

Instrument after(const Instrument& instrument, const WhatIfWords& words) {
    return apply_change(instrument, read_what_ifs(words, instrument).change);
}

// The message of what `f` refuses; "(accepted)" if it does not.
template <class F>
std::string refused(F&& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "(accepted)";
}

std::string refusal(const Instrument& instrument, const WhatIfWords& words) {
    return refused([&] { after(instrument, words); });
}

TEST(InstrumentUnits, ThouAndFractionsInAnyDenominatorAreInches) {
    EXPECT_DOUBLE_EQ(parse_quantity("12 thou", Quantity::length, "k"), 12e-3 * kIn);
    EXPECT_DOUBLE_EQ(parse_quantity("3/32 in", Quantity::length, "k"), 3.0 / 32.0 * kIn);
    EXPECT_DOUBLE_EQ(parse_quantity("5/64\"", Quantity::length, "k"), 5.0 / 64.0 * kIn);
    EXPECT_DOUBLE_EQ(parse_quantity("1/8in", Quantity::length, "k"), kIn / 8.0);
    // A bare number in the unit asked for, and the reading said back with mm beside.
    const LengthAsRead relief = read_length("0.012", "in", "--relief");
    EXPECT_DOUBLE_EQ(relief.metres, 0.012 * kIn);
    EXPECT_EQ(relief.as_read, "0.012 in (0.305 mm)");
    EXPECT_EQ(read_length("3/32in", "mm", "k").as_read, "3/32 in (2.381 mm)");
    EXPECT_EQ(read_length("2.2", "mm", "k").as_read, "2.2 mm");
    EXPECT_EQ(read_length("+2 thou", "mm", "k").as_read, "+2 thou (0.051 mm)");
    EXPECT_THROW(read_length("2 furlongs", "in", "k"), InputError);
    EXPECT_THROW(read_length("3/0 in", "in", "k"), InputError);
}

TEST(InstrumentFile, TheFilesUnitsAreThoseOfItsFirstStringsGaps) {
    EXPECT_EQ(load_instrument("jazz-bass").units, ShopUnits::mm);
    EXPECT_EQ(inch_bass().units, ShopUnits::sixty_fourths);
    // Any fraction of an inch is a gauge's reading; thou is a feeler gauge's.
    std::string text = testing::replaced(bass_text(), "action12 = \"2.7 mm\"", "action12 = \"3/32 in\"");
    text = testing::replaced(text, "nut = \"0.75 mm\"", "nut = \"0.030 in\"");
    EXPECT_EQ(parse_instrument(text, "t.toml", DataSource::builtin()).units, ShopUnits::sixty_fourths);
    text = testing::replaced(bass_text(), "nut = \"0.75 mm\"", "nut = \"30 thou\"");
    text = testing::replaced(text, "action12 = \"2.7 mm\"", "action12 = \"106 thou\"");
    const Instrument thou = parse_instrument(text, "t.toml", DataSource::builtin());
    EXPECT_EQ(thou.units, ShopUnits::thousandths);
    EXPECT_NEAR(StringNeck(thou, 0).gap(1), 30e-3 * kIn, 1e-15);
}

TEST(InstrumentFile, AnActionAtAnotherFretPointsToActionAndActionFret) {
    const std::string text = testing::replaced(bass_text(), "action12 = \"2.7 mm\"", "action17 = \"3/32 in\"");
    const std::string what = refused([&] { parse_instrument(text, "t.toml", DataSource::builtin()); });
    EXPECT_NE(what.find("string[0].action17"), std::string::npos) << what;
    EXPECT_NE(what.find("action_fret = 17"), std::string::npos) << what;
    EXPECT_EQ(what.find("did you mean"), std::string::npos) << what;
    // Beside a valid action12 too, it is no typo of it.
    const std::string both = testing::replaced(bass_text(), "action12 = \"2.7 mm\"", "action12 = \"2.7 mm\"\naction17 = \"3 mm\"");
    testing::expect_instrument_refused(both, "action_fret = 17");
}

TEST(SetupWhatIf, ABareNumberIsInTheInstrumentFilesUnits) {
    const Instrument inch = inch_bass();
    WhatIfWords relief;
    relief.relief = "0.012";
    const WhatIfReading read = read_what_ifs(relief, inch);
    ASSERT_EQ(read.as_read.size(), 1u);
    EXPECT_EQ(read.as_read[0], "relief: 0.012 in (0.305 mm)");
    EXPECT_NEAR(StringNeck(apply_change(inch, read.change), 0).relief_gap(8), 0.012 * kIn, 1e-12);
    WhatIfWords action;
    action.action12 = {"E=5/64"};
    EXPECT_NEAR(StringNeck(after(inch, action), 0).gap(12), 5.0 / 64.0 * kIn, 1e-12);
    // In a mm file a bare number is mm; a unit said is taken as said in either.
    const Instrument& mm = jazz_bass();
    EXPECT_NEAR(StringNeck(after(mm, relief), 0).relief_gap(8), 0.012e-3, 1e-12);
    relief.relief = "12thou";
    EXPECT_NEAR(StringNeck(after(mm, relief), 0).relief_gap(8), 12e-3 * kIn, 1e-12);
    EXPECT_NEAR(StringNeck(after(inch, relief), 0).relief_gap(8), 12e-3 * kIn, 1e-12);
    WhatIfWords offset;
    offset.fret_offsets = {"15=0.003"};
    EXPECT_NEAR(StringNeck(after(inch, offset), 0).fret_top(15) - StringNeck(inch, 0).fret_top(15), 0.003 * kIn, 1e-15);
}

TEST(SetupWhatIf, TheActionIsSetAtTheFretAskedByItsSaddle) {
    const Instrument& bass = jazz_bass();
    const StringNeck before(bass, 0);
    WhatIfWords w;
    w.action = {"17:E=3/32in"};
    const WhatIfReading read = read_what_ifs(w, bass);
    ASSERT_EQ(read.as_read.size(), 1u);
    EXPECT_EQ(read.as_read[0], "action at fret 17, E: 3/32 in (2.381 mm)");
    const Instrument set = apply_change(bass, read.change);
    const StringNeck now(set, 0);
    EXPECT_NEAR(now.gap(17), 3.0 / 32.0 * kIn, 1e-9);
    EXPECT_NE(std::abs(before.gap(17) - now.gap(17)), 0.0);  // it did move
    // The nut, the neck and the other strings held; the saddle moved L / x_17 times the gap.
    EXPECT_NEAR(now.nut_height(), before.nut_height(), 1e-15);
    EXPECT_NEAR(now.relief_gap(8), before.relief_gap(8), 1e-15);
    EXPECT_NEAR(StringNeck(set, 1).gap(17), StringNeck(bass, 1).gap(17), 1e-15);
    EXPECT_NEAR(now.saddle_height() - before.saddle_height(),
                (now.gap(17) - before.gap(17)) * bass.strings[0].scale_length_m / now.fret_x(17), 1e-9);
    // After a relief what-if, the action is still where it was asked for (relief first).
    w.relief = "0.3mm";
    EXPECT_NEAR(StringNeck(after(bass, w), 0).gap(17), 3.0 / 32.0 * kIn, 1e-9);
    // --action12 is fret 12's shorthand: the same neck.
    WhatIfWords at12, shorthand;
    at12.action = {"12:E=2.2mm"};
    shorthand.action12 = {"E=2.2"};
    EXPECT_EQ(StringNeck(after(bass, at12), 0).saddle_height(), StringNeck(after(bass, shorthand), 0).saddle_height());
    EXPECT_NEAR(StringNeck(after(bass, shorthand), 0).gap(12), 2.2e-3, 1e-15);
    // Out of form or range: the option, and the form or the range it takes.
    for (const auto& [bad, says] : std::vector<std::pair<std::string, std::string>>{
             {"17E=2mm", "FRET:STRING=LENGTH"},
             {"17:E", "FRET:STRING=LENGTH"},
             {"1:E=2mm", "[2, 20]"},
             {"25:E=2mm", "[2, 20]"},
             {"x:E=2mm", "[2, 20]"},
             {"17:Q=2mm", "E, A, D, G"},
             {"17:E=2 furlongs", "units"},
             {"17:E=20mm", "[0.01, 10] mm"}}) {
        WhatIfWords b;
        b.action = {bad};
        const std::string what = refusal(bass, b);
        EXPECT_NE(what.find("--action"), std::string::npos) << bad << ": " << what;
        EXPECT_NE(what.find(says), std::string::npos) << bad << ": " << what;
    }
}

TEST(SetupWhatIf, RelativeMovesComposeWithTheFilesValues) {
    const Instrument& bass = jazz_bass();
    WhatIfWords saddle;
    saddle.saddle_change = {"E=-0.25mm"};
    const Instrument lowered = after(bass, saddle);
    const StringNeck before(bass, 0);
    EXPECT_NEAR(StringNeck(lowered, 0).saddle_height(), before.saddle_height() - 0.25e-3, 1e-15);
    EXPECT_NEAR(StringNeck(lowered, 0).nut_height(), before.nut_height(), 1e-15);
    EXPECT_NEAR(StringNeck(lowered, 1).saddle_height(), StringNeck(bass, 1).saddle_height(), 1e-15);
    WhatIfWords relief;
    relief.relief_change = "+0.002in";
    const Instrument looser = after(bass, relief);
    EXPECT_NEAR(StringNeck(looser, 0).relief_gap(8), before.relief_gap(8) + 0.002 * kIn, 1e-12);
    EXPECT_NEAR(StringNeck(looser, 0).saddle_height(), before.saddle_height(), 1e-15);
    WhatIfWords nut;
    nut.nut_change = {"E=-2thou"};
    EXPECT_NEAR(StringNeck(after(bass, nut), 0).nut_height(), before.nut_height() - 2e-3 * kIn, 1e-15);
    // In an inch file a bare change is in inches.
    const Instrument inch = inch_bass();
    saddle.saddle_change = {"E=-0.01"};
    EXPECT_NEAR(StringNeck(after(inch, saddle), 0).saddle_height(), StringNeck(inch, 0).saddle_height() - 0.01 * kIn,
                1e-15);
    // One end set twice, or the truss rod twice, is refused naming both.
    WhatIfWords twice;
    twice.saddle = {"E=12mm"};
    twice.saddle_change = {"E=-0.25mm"};
    EXPECT_NE(refusal(bass, twice).find("--saddle E already sets string E's saddle"), std::string::npos)
        << refusal(bass, twice);
    twice = {};
    twice.action12 = {"E=2.2mm"};
    twice.action = {"17:E=2.4mm"};
    EXPECT_NE(refusal(bass, twice).find("--action12 E already sets"), std::string::npos) << refusal(bass, twice);
    twice = {};
    twice.relief = "0.3mm";
    twice.relief_change = "0.1mm";
    EXPECT_NE(refusal(bass, twice).find("give one"), std::string::npos) << refusal(bass, twice);
    WhatIfWords far;
    far.relief_change = "2mm";
    EXPECT_NE(refusal(bass, far).find("--relief-change = 2 mm is out of range: must be in [-1, 1] mm"), std::string::npos)
        << refusal(bass, far);
    far = {};
    far.saddle_change = {"E=-6mm"};
    EXPECT_NE(refusal(bass, far).find("--saddle-change E = -6 mm is out of range: must be in [-5, 5] mm"),
              std::string::npos)
        << refusal(bass, far);
    far.saddle_change = {"E"};
    EXPECT_NE(refusal(bass, far).find("--saddle-change E: give STRING=LENGTH"), std::string::npos) << refusal(bass, far);
    far = {};
    far.nut_change = {"E=-1mm"};  // the open string would lie on fret 1
    EXPECT_NE(refusal(bass, far).find("--nut-change E"), std::string::npos) << refusal(bass, far);
}

}  // namespace
}  // namespace fretbuzz

namespace fretbuzz {
namespace {

// The jazz bass with what a turn of its screws does: a truss rod measured at 0.2 mm of relief
// a turn, saddles on 4-40 screws (1/40 in a turn).
Instrument adjustable_bass() {
    return parse_instrument(bass_text() + "\n[adjusters]\ntruss_rod_turn = \"0.2 mm\"\nsaddle_screw_pitch = \"1/40 in\"\n",
                            "adjustable-bass.toml", DataSource::builtin());
}

TEST(SetupWhatIf, ATurnMovesByWhatTheFileSaysATurnDoes) {
    const Instrument bass = adjustable_bass();
    const StringNeck before(bass, 0);
    // A quarter turn tighter: 0.05 mm less relief, the saddles where they were.
    WhatIfWords rod;
    rod.truss_rod_turns = "+1/4";
    const WhatIfReading read = read_what_ifs(rod, bass);
    ASSERT_EQ(read.as_read.size(), 1u);
    EXPECT_EQ(read.as_read[0], "truss rod: 0.25 turn (+ tighter)");
    const Instrument tighter = apply_change(bass, read.change);
    EXPECT_NEAR(StringNeck(tighter, 0).relief_gap(8), before.relief_gap(8) - 0.05e-3, 1e-12);
    EXPECT_NEAR(StringNeck(tighter, 0).saddle_height(), before.saddle_height(), 1e-15);
    // The same as the relative move it stands for, under every string.
    WhatIfWords same;
    same.relief_change = "-0.05mm";
    const Instrument moved = after(bass, same);
    for (std::size_t s = 0; s < bass.strings.size(); ++s)
        EXPECT_NEAR(StringNeck(tighter, s).fret_top(12), StringNeck(moved, s).fret_top(12), 1e-15) << s;
    rod.truss_rod_turns = "-1/2 turn";  // looser
    EXPECT_NEAR(StringNeck(after(bass, rod), 0).relief_gap(8), before.relief_gap(8) + 0.1e-3, 1e-12);
    // Half a turn down on the E saddle's screws: 1/80 in lower, the other saddles kept.
    WhatIfWords saddle;
    saddle.saddle_turns = {"E=-1/2"};
    const Instrument lowered = after(bass, saddle);
    EXPECT_NEAR(StringNeck(lowered, 0).saddle_height(), before.saddle_height() - 0.5 * kIn / 40.0, 1e-15);
    EXPECT_NEAR(StringNeck(lowered, 1).saddle_height(), StringNeck(bass, 1).saddle_height(), 1e-15);
    // The map's record of its what-ifs (and --calibrate's refusal of any) hold the turns too.
    WhatIfWords both = rod;
    both.saddle_turns = saddle.saddle_turns;
    EXPECT_EQ(both.words(), (std::vector<std::string>{"--truss-rod-turns -1/2 turn", "--saddle-turns E=-1/2"}));
}

// A file that measures the action at fret 17 keeps saying so through the what-ifs, whose
// pinned ends would otherwise forget where it was measured.
TEST(SetupWhatIf, TheFretTheFileMeasuresAtIsKept) {
    const std::string text = testing::replaced(bass_text(), "action12 = \"2.7 mm\"", "action = \"3/32 in\"\naction_fret = 17");
    const Instrument fender = parse_instrument(text, "fender.toml", DataSource::builtin());
    EXPECT_EQ(fender.strings[0].action_fret, 17u);
    EXPECT_EQ(fender.strings[1].action_fret, 12u);
    WhatIfWords w;
    w.relief = "0.3mm";
    EXPECT_EQ(after(fender, w).strings[0].action_fret, 17u);
    EXPECT_NEAR(StringNeck(fender, 0).gap(17), 3.0 / 32.0 * kIn, 1e-12);
}

TEST(SetupWhatIf, TurnsAreRefusedWithoutWhatATurnDoesAndOutOfRange) {
    const Instrument& plain = jazz_bass();
    WhatIfWords rod;
    rod.truss_rod_turns = "1/4";
    EXPECT_NE(refusal(plain, rod).find("--truss-rod-turns needs adjusters.truss_rod_turn"), std::string::npos)
        << refusal(plain, rod);
    WhatIfWords saddle;
    saddle.saddle_turns = {"E=1"};
    EXPECT_NE(refusal(plain, saddle).find("--saddle-turns E needs adjusters.saddle_screw_pitch"), std::string::npos)
        << refusal(plain, saddle);
    const Instrument bass = adjustable_bass();
    for (const char* bad : {"3", "-2.5", "x", "1/0", "1/", "--1", "1/4 turnz", ""}) {
        rod.truss_rod_turns = bad;
        if (rod.truss_rod_turns.empty()) continue;  // (empty: no what-if)
        EXPECT_NE(refusal(bass, rod).find("--truss-rod-turns " + std::string(bad) + ": turns must be"), std::string::npos)
            << bad << ": " << refusal(bass, rod);
        EXPECT_NE(refusal(bass, rod).find("in [-2, 2]"), std::string::npos) << bad;
    }
    WhatIfWords twice;
    twice.truss_rod_turns = "1/4";
    twice.relief_change = "0.1mm";
    EXPECT_NE(refusal(bass, twice).find("each set the truss rod: give one of them"), std::string::npos)
        << refusal(bass, twice);
    twice = {};
    twice.saddle_turns = {"E=1"};
    twice.saddle_change = {"E=-0.25mm"};
    EXPECT_NE(refusal(bass, twice).find("already sets string E's saddle"), std::string::npos) << refusal(bass, twice);
    saddle.saddle_turns = {"E=21"};
    EXPECT_NE(refusal(bass, saddle).find("in [-20, 20]"), std::string::npos) << refusal(bass, saddle);
    saddle.saddle_turns = {"Q=1"};
    EXPECT_NE(refusal(bass, saddle).find("--saddle-turns Q=1"), std::string::npos) << refusal(bass, saddle);
    // The file's values are checked when it is read, naming the key.
    const std::string far = refused([] {
        parse_instrument(bass_text() + "\n[adjusters]\ntruss_rod_turn = \"5 mm\"\n", "far.toml", DataSource::builtin());
    });
    EXPECT_NE(far.find("adjusters.truss_rod_turn"), std::string::npos) << far;
    EXPECT_NE(far.find("(0, 2] mm"), std::string::npos) << far;
}

TEST(SetupAdvice, ItsMovesAreSaidInTurnsWhereTheFileSaysWhatATurnDoes) {
    EXPECT_EQ(turns_text(0.75), "3/4 turn clockwise");
    EXPECT_EQ(turns_text(-1.25), "1 1/4 turns anticlockwise");
    EXPECT_EQ(turns_text(2.0), "2 turns clockwise");
    EXPECT_EQ(turns_text(0.04), "less than 1/8 turn");
    EXPECT_EQ(turns_text(screw_turns_for(1e-3, 0.0)), "");
    Advice advice;
    advice.adjusters = adjustable_bass().adjusters;
    ActionAdvice a;
    a.string = "E";
    a.current_m = 2.4e-3;
    a.lowest_clean_m = 2.6e-3;
    a.saddle_change_m = 0.75 * kIn / 40.0;
    advice.actions = {a};
    advice.relief.fret = 8;
    advice.relief.current_m = 0.5e-3;
    advice.relief.best_m = 0.3e-3;  // 0.2 mm less: a full turn tighter
    const std::string text = advice_text(advice);
    EXPECT_NE(text.find("raise the saddle 0.48 mm (3/4 turn clockwise of its height screws)"), std::string::npos) << text;
    EXPECT_NE(text.find("the truss rod 1 turn clockwise"), std::string::npos) << text;
    advice.adjusters = {};
    EXPECT_EQ(advice_text(advice).find("turn"), std::string::npos) << advice_text(advice);
}

}  // namespace
}  // namespace fretbuzz
