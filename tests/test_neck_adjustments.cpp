// Instruments as they are adjusted: a capo, a compound (conical) radius, relief that follows
// the strings' pull (drop D, a heavier set: the neck as a beam, geometry/NeckBeam.hpp), and
// the instrument file's words: luthiers' fractions, the inch mark, misspelt keys named with
// the key they stand for, bad values refused with exit 2 naming key and range, and
// `fretbuzz show` printing a built-in instrument.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "SetupTestSupport.hpp"
#include "TestSupport.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/geometry/ObstacleProfile.hpp"
#include "fretbuzz/geometry/SimpleObstacles.hpp"
#include "fretbuzz/input/BuiltinFiles.hpp"
#include "fretbuzz/input/InstrumentFile.hpp"
#include "fretbuzz/input/InstrumentUnits.hpp"
#include "fretbuzz/model/TautString.hpp"
#include "fretbuzz/setup/Attack.hpp"
#include "fretbuzz/setup/BuzzMap.hpp"
#include "fretbuzz/setup/StringNeck.hpp"
#include "fretbuzz/setup/WhatIf.hpp"

namespace fretbuzz {
namespace {

using testing::replaced;
constexpr double kInch = 0.0254;

std::string builtin_text(const std::string& name) { return std::string(*find_builtin_file("instruments/" + name + ".toml")); }

// The bow a parabola of depth 1 has at x over the span [0, last].
double unit_bow(double x, double last) { return 4.0 * (x / last) * (1.0 - x / last); }

// Drop D: the E string a tone down pulls less, by T (1 - (D2 / E2)^2); the neck, its truss rod
// as it was, bows less by that times e l^2 / (8 EI), and every note's obstacle shows the frets
// risen by that bow's shape (the string's ends stay where they are).
TEST(ReliefFollowsThePull, DropDLowersTheReliefByWhatTheNeckModelSays) {
    const Instrument guitar = load_instrument("electric-guitar");
    SetupChange drop_d;
    drop_d.pitch_hz = {{"E", parse_quantity("D2", Quantity::frequency, "test")}};
    const Instrument dropped = apply_change(guitar, drop_d);
    const InstrumentString& e = guitar.strings[0];
    const double less = e.tension_n - TautString::tuned_with_mass(e.scale_length_m, e.linear_density, 73.41619197935).tension_n;
    EXPECT_NEAR(strings_pull(guitar) - strings_pull(dropped), less, 1e-9);
    EXPECT_NEAR(less, 16.06, 0.01);  // 17.5 lb (77.8 N) times 1 - (73.42 / 82.41)^2

    const StringNeck before(with_pinned_string_ends(guitar), 0), after(dropped, 0);
    const double span = before.fret_x(before.fret_count());
    const double bow = -less * guitar.neck.beam.bow_per_newton(span);  // + down: it bows less
    EXPECT_NEAR(bow, -less * 0.013 * span * span / (8.0 * 486.2), 1e-8);
    const std::size_t m = relief_fret(guitar);
    EXPECT_NEAR(after.relief_gap(m) - before.relief_gap(m), bow * relief_gap_per_bow(before, m), 1e-15);
    EXPECT_LT(after.relief_gap(m), before.relief_gap(m));
    const auto report = pull_change(guitar, dropped);
    ASSERT_TRUE(report.has_value());
    EXPECT_NEAR(report->bow_m, bow, 1e-15);
    EXPECT_NEAR(report->relief_after_m - report->relief_before_m, after.relief_gap(m) - before.relief_gap(m), 1e-15);

    // The open note's obstacle: each fret's top risen by -bow u(x_n), the string where it was.
    const Grid grid{before.length(), static_cast<std::size_t>(std::lround(before.length() / 1e-3)) - 1};
    const std::vector<double> g0 = before.note_obstacle(0, grid), g1 = after.note_obstacle(0, grid);
    for (std::size_t n = 1; n < before.fret_count(); ++n) {
        const std::size_t i = nearest_grid_point(grid, before.fret_x(n));
        EXPECT_NEAR(g1[i] - g0[i], -bow * unit_bow(before.fret_x(n), span), 1e-15) << "fret " << n;
    }
    // Every string sees it (the neck is one beam), the B string too though it was not retuned.
    const StringNeck b_before(with_pinned_string_ends(guitar), 4), b_after(dropped, 4);
    const double b_span = b_before.fret_x(b_before.fret_count());
    const double b_bow = -less * guitar.neck.beam.bow_per_newton(b_span);
    EXPECT_NEAR(b_after.fret_top(8) - b_before.fret_top(8), -b_bow * unit_bow(b_before.fret_x(8), b_span), 1e-15);
}

// A heavier set (11-49 for 10-46) pulls more: the relief grows; a stiffer neck bows less.
TEST(ReliefFollowsThePull, AHeavierSetDeepensTheReliefAndAStifferNeckLess) {
    Instrument guitar = load_instrument("electric-guitar");
    SetupChange heavier;
    heavier.string_set = "daddario-exl115";
    const Instrument strung = apply_change(guitar, heavier);
    EXPECT_GT(strings_pull(strung), strings_pull(guitar) + 60.0);
    const std::size_t m = relief_fret(guitar);
    const double deeper = StringNeck(strung, 0).relief_gap(m) - StringNeck(guitar, 0).relief_gap(m);
    EXPECT_GT(deeper, 0.0);
    EXPECT_NEAR(strung.strings[0].gauge_m, 0.049 * kInch, 1e-15);
    guitar.neck.beam.bending_stiffness_n_m2 *= 2.0;
    const Instrument stiff = apply_change(guitar, heavier);
    EXPECT_NEAR(StringNeck(stiff, 0).relief_gap(m) - StringNeck(guitar, 0).relief_gap(m), 0.5 * deeper, 1e-15);
    // Its own strings, as the file tunes them, leave the measured relief alone.
    EXPECT_NEAR(StringNeck(guitar, 0).relief_gap(m), 0.010 * kInch, 1e-15);
}

// A capo on fret 3: the map plays frets 3 and up (fret 3 is the open string), refuses frets
// below it, and its note at the capo is the note stopped at fret 3 without a capo.
TEST(NeckAdjustments, ACapoStopsTheOpenStringAtItsFret) {
    const std::string base = builtin_text("jazz-bass");
    Instrument capo = parse_instrument(replaced(base, "frets = 20", "frets = 20\ncapo = 3"), "capo.toml",
                                       DataSource::builtin());
    EXPECT_EQ(capo.neck.capo, 3u);
    capo.bench.sample_rate_hz = 5e5;
    capo.bench.duration_s = 0.05;
    capo.bench.grid_step_m = 2e-3;
    capo.attack.ensemble = 1;
    MapRequest request;
    request.strings = {3};
    request.attacks = parse_attacks("hard", capo.attack);
    const std::vector<MapNote> notes = map_notes(capo, request);
    ASSERT_EQ(notes.size(), 18u);  // frets 3 to 20
    EXPECT_EQ(notes.front().fret, 3u);
    request.frets = {1, 5};
    try {
        map_notes(capo, request);
        ADD_FAILURE() << "a fret below the capo was played";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("neck.capo"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("--frets"), std::string::npos) << e.what();
    }
    request.frets = {3};
    Instrument free = capo;
    free.neck.capo = 0;
    const NoteVerdict at_capo = play_map(capo, request).notes.at(0), stopped = play_map(free, request).notes.at(0);
    EXPECT_EQ(at_capo.pluck_db.size(), 1u);
    EXPECT_EQ(at_capo.buzz_fraction, stopped.buzz_fraction);
    EXPECT_EQ(at_capo.clearance_m, stopped.clearance_m);
    if (std::isfinite(stopped.buzz_db)) {
        EXPECT_EQ(at_capo.buzz_db, stopped.buzz_db);
    }
    testing::expect_instrument_refused(replaced(base, "frets = 20", "frets = 20\ncapo = 20"), "neck.capo", "[1, 19]");
}

// A compound radius, 7.25 in at the nut to 16 in at the last fret: a cone. The outer string's
// crown is the cone's, neither cylinder's; the string down the middle sees none.
TEST(NeckAdjustments, ACompoundRadiusIsAConeFromNutToLastFret) {
    const std::string flat = replaced(replaced(builtin_text("electric-guitar"), "[neck.relief]\ngap = \"0.010 in\"\nfret = 8\n", ""),
                                      "radius = \"9.5 in\"", "radius = RADIUS");
    const auto neck = [&](const std::string& radius, std::size_t string) {
        Instrument g = parse_instrument(replaced(flat, "RADIUS", radius), "g.toml", DataSource::builtin());
        g.neck.relief_pull_n.reset();
        g.strings.resize(5);  // an odd count: the third string runs down the middle
        for (auto& s : g.strings) s.bridge = {StringEnd::Form::gap_over_fret, 2e-3, 12};
        return std::make_pair(g, StringNeck(g, string));
    };
    // (named members, not a structured binding: the lambda below captures them)
    const auto made = neck("[\"7.25 in\", \"16 in\"]", 0);
    const Instrument& g = made.first;
    const StringNeck& cone = made.second;
    EXPECT_NEAR(*g.neck.radius_m, 7.25 * kInch, 1e-15);
    EXPECT_NEAR(*g.neck.radius_last_fret_m, 16.0 * kInch, 1e-15);
    const double last = cone.fret_x(cone.fret_count()), length = cone.length();
    const auto drop = [&](double at) {
        const double y = -0.5 * (g.neck.nut_width_m + (g.neck.bridge_spacing_m - g.neck.nut_width_m) * at / length);
        const double r = 7.25 * kInch + (16.0 - 7.25) * kInch * at / last;
        return r - std::sqrt(r * r - y * y);
    };
    const StringNeck narrow = neck("\"7.25 in\"", 0).second, wide = neck("\"16 in\"", 0).second;
    for (std::size_t n = 2; n + 2 < cone.fret_count(); n += 3) {
        const double x = cone.fret_x(n);
        EXPECT_NEAR(cone.fret_line(n), drop(0.0) + (drop(last) - drop(0.0)) * x / last - drop(x), 1e-15) << n;
        // (not either cylinder's: the radius growing along the string bends its path too)
        EXPECT_GT(std::abs(cone.fret_line(n) - narrow.fret_line(n)), 1e-6) << n;
        EXPECT_GT(std::abs(cone.fret_line(n) - wide.fret_line(n)), 1e-6) << n;
    }
    EXPECT_NEAR(neck("[\"7.25 in\", \"16 in\"]", 2).second.fret_line(10), 0.0, 1e-18);
    testing::expect_instrument_refused(replaced(flat, "RADIUS", "[\"10 in\"]"), "neck.radius", "one radius or two");
    testing::expect_instrument_refused(replaced(flat, "RADIUS", "[\"10 in\", \"9000 mm\"]"), "neck.radius[1]",
                                       "[50, 5000] mm");
}

TEST(InstrumentWords, LuthiersFractionsAndTheInchMarkRead) {
    EXPECT_DOUBLE_EQ(parse_quantity("4.5/64 in", Quantity::length, "k"), 4.5 / 64.0 * kInch);
    EXPECT_DOUBLE_EQ(parse_quantity("5/64\"", Quantity::length, "k"), 5.0 / 64.0 * kInch);
    EXPECT_DOUBLE_EQ(parse_quantity("1 3/16\"", Quantity::length, "k"), 1.1875 * kInch);
    EXPECT_THROW(parse_quantity("5/64\"", Quantity::force, "k"), InputError);
    EXPECT_THROW(parse_quantity("5/6.4 in", Quantity::length, "k"), InputError);
    const std::string base = builtin_text("jazz-bass");
    const Instrument bass =
        parse_instrument(replaced(base, "action12 = \"2.7 mm\"", "action12 = '7/64\"'"), "t.toml", DataSource::builtin());
    EXPECT_NEAR(StringNeck(bass, 0).gap(12), 7.0 / 64.0 * kInch, 1e-15);
    // Unquoted, it is no TOML; the message says how a value with a unit is written.
    testing::expect_instrument_refused(replaced(base, "action12 = \"2.7 mm\"", "action12 = 5/64\""), "quoted string",
                                       "\"4.5/64 in\"");
}

TEST(InstrumentWords, AMisspeltKeyIsNamedWithTheKeyItStandsFor) {
    const std::string base = builtin_text("jazz-bass");
    // A required key misspelt: not "action12 is missing".
    testing::expect_instrument_refused(replaced(base, "action12 = \"2.7 mm\"", "acton12 = \"2.7 mm\""),
                                       "unknown key string[0].acton12: did you mean string[0].action12?");
    testing::expect_instrument_refused(replaced(base, "nut = \"0.75 mm\"", "nutt = \"0.75 mm\""),
                                       "unknown key string[0].nutt: did you mean string[0].nut?");
    testing::expect_instrument_refused(replaced(base, "fret_height = \"1.2 mm\"", "fret_hieght = \"1.2 mm\""),
                                       "unknown key neck.fret_hieght: did you mean neck.fret_height?");
    // An optional one: read past, then named.
    testing::expect_instrument_refused(replaced(base, "core = \"0.038 in\"", "core = \"0.038 in\"\ngauje = \"0.1 in\""),
                                       "unknown key string[0].gauje: did you mean string[0].gauge?");
    // A key like no other is named alone (and an unrelated missing key is not blamed on it).
    testing::expect_instrument_refused(replaced(base, "board_end = \"600 mm\"", "board_end = \"600 mm\"\nwood = \"maple\""),
                                       "unknown key neck.wood (check its spelling)");
}

// Bad values through the program: exit 2, the key and its range named, nothing written.
TEST(InstrumentWords, BadValuesExitTwoNamingKeyAndRange) {
    testing::ScratchDir dir("neck-adjustments");
    const std::string base = builtin_text("jazz-bass");
    int files = 0;
    const auto file = [&](const std::string& text) {
        const auto path = dir.path() / ("bad" + std::to_string(++files) + ".toml");
        std::ofstream(path) << text;
        return path.string();
    };
    const std::string out = (dir.path() / "never").string();
    const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
        {file(replaced(base, "frets = 20", "frets = 20\ncapo = 25")), {"neck.capo", "[1, 19]"}},
        {file(replaced(base, "frets = 20", "frets = 20\nradius = [\"10 in\", \"1 mm\"]")), {"neck.radius[1]", "[50, 5000] mm"}},
        {file(replaced(base, "frets = 20", "frets = 20\nstiffness = \"5 N m^2\"")), {"neck.stiffness", "[20, 20000] N m^2"}},
        {file(replaced(base, "frets = 20", "frets = 20\npull_height = \"80 mm\"")), {"neck.pull_height", "(0, 50] mm"}},
        {file(replaced(base, "core = \"0.038 in\"", "core = \"6 mm\"")), {"string[0].core", "(0, 5] mm"}},
        {file(replaced(base, "action12 = \"2.7 mm\"", "acton12 = \"2.7 mm\"")), {"did you mean string[0].action12"}},
        {file(replaced(base, "action12 = \"2.7 mm\"", "action12 = 7/64\"")), {"quoted string", "'5/64\"'"}},
        {"jazz-bass --tune E=Z9", {"--tune E", "\"Z9\""}},
        {"jazz-bass --tune E=2500Hz", {"--tune E", "[20, 2000] Hz"}},
        {"jazz-bass --tune E=E3", {"--tune E", "[1, 1500] N"}},
        {"jazz-bass --set daddario-exl170-5", {"--set daddario-exl170-5", "5 strings"}},
        {"jazz-bass --set nylon", {"--set", "no such string set"}},
    };
    for (const auto& [arguments, says] : cases) {
        const auto r = testing::run_cli("setup " + arguments + " --out " + out);
        EXPECT_EQ(r.exit_code, 2) << arguments << "\n" << r.output;
        for (const std::string& s : says) EXPECT_NE(r.output.find(s), std::string::npos) << arguments << "\n" << r.output;
        EXPECT_FALSE(std::filesystem::exists(out)) << arguments;
    }
}

TEST(InstrumentWords, ShowPrintsABuiltInInstrument) {
    const auto bass = testing::run_cli("show jazz-bass");
    EXPECT_EQ(bass.exit_code, 0) << bass.output;
    EXPECT_EQ(bass.output, builtin_text("jazz-bass"));
    const auto neck = testing::run_cli("show --instrument bass-neck");
    EXPECT_EQ(neck.output, builtin_text("bass-neck"));
    EXPECT_NE(testing::run_cli("show bass-neck").output, neck.output);  // the case of that name
    const auto none = testing::run_cli("show banjo");
    EXPECT_EQ(none.exit_code, 2);
    EXPECT_NE(none.output.find("bass-5"), std::string::npos) << none.output;
    EXPECT_NE(none.output.find("bass-pop"), std::string::npos) << none.output;
}

}  // namespace
}  // namespace fretbuzz
