// Instrument files and the neck's geometry under each string: values with units, what a
// luthier measures read back from the geometry (gap over fret 1 and 12, relief under the
// first string), the single-string built-in equal to the bass-neck case's neck, fret tops
// seen from every stopped string, the radius's crown, multiscale frets, and refusals that
// name the key and its range.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <regex>
#include <set>
#include <sstream>

#include "SetupTestSupport.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/geometry/SimpleObstacles.hpp"
#include "fretbuzz/input/BuiltinFiles.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/InstrumentFile.hpp"
#include "fretbuzz/input/InstrumentUnits.hpp"
#include "fretbuzz/setup/Attack.hpp"
#include "fretbuzz/setup/InstrumentGeometry.hpp"
#include "fretbuzz/setup/NoteCase.hpp"
#include "fretbuzz/setup/StringNeck.hpp"
#include "fretbuzz/setup/WhatIf.hpp"

namespace fretbuzz {
namespace {

TEST(InstrumentUnits, LengthsForcesAndNotesInTheirUnits) {
    EXPECT_DOUBLE_EQ(parse_quantity("2.4 mm", Quantity::length, "k"), 2.4e-3);
    EXPECT_DOUBLE_EQ(parse_quantity("5/64 in", Quantity::length, "k"), 5.0 / 64.0 * 0.0254);
    EXPECT_DOUBLE_EQ(parse_quantity("1 3/16 in", Quantity::length, "k"), 1.1875 * 0.0254);
    EXPECT_DOUBLE_EQ(parse_quantity("0.094 in", Quantity::length, "k"), 0.094 * 0.0254);
    EXPECT_DOUBLE_EQ(parse_quantity("34 in", Quantity::length, "k"), 0.8636);
    EXPECT_DOUBLE_EQ(parse_quantity("43.1 lb", Quantity::force, "k"), 43.1 * 4.4482216152605);
    EXPECT_NEAR(parse_quantity("E1", Quantity::frequency, "k"), 41.2034, 1e-4);
    EXPECT_NEAR(parse_quantity("G2", Quantity::frequency, "k"), 97.9989, 1e-4);
    EXPECT_NEAR(parse_quantity("Bb3", Quantity::frequency, "k"), 233.082, 1e-3);
    EXPECT_DOUBLE_EQ(parse_quantity("1 MHz", Quantity::frequency, "k"), 1e6);
    EXPECT_DOUBLE_EQ(parse_quantity_or("0.3", Quantity::length, "mm", "--relief"), 0.3e-3);
    for (const char* bad : {"2.4", "2.4 furlongs", "mm", "1/0 in", "nan mm", "H2"}) {
        try {
            parse_quantity(bad, bad[0] == 'H' ? Quantity::frequency : Quantity::length, "neck.fret_height");
            ADD_FAILURE() << bad << " was accepted";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find("neck.fret_height"), std::string::npos) << e.what();
        }
    }
}

TEST(InstrumentFile, BuiltInsLoadWithTheirStrings) {
    std::vector<std::string> names;
    for (const auto& info : builtin_instruments()) names.push_back(info.name);
    for (const char* name : {"jazz-bass", "electric-guitar", "bass-neck"})
        EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
    const Instrument bass = load_instrument("jazz-bass");
    ASSERT_EQ(bass.strings.size(), 4u);
    EXPECT_EQ(bass.strings[0].name, "E");
    EXPECT_NEAR(bass.strings[0].frequency_hz, 41.2034, 1e-3);
    // The set's unit weight at its own scale and pitch gives back the published tension there.
    const StringSet exl170 = builtin_string_set("daddario-exl170", "test");
    EXPECT_NEAR(bass.strings[0].tension_n * std::pow(0.8636 / 0.863, 2), exl170.strings[0].tension_n, 1e-9);
    // The G string is the paper's measured one, its tension and mass as given.
    EXPECT_DOUBLE_EQ(bass.strings[3].tension_n, 191.6);
    EXPECT_NEAR(bass.strings[3].frequency_hz, 97.97, 0.2);
    const Instrument guitar = load_instrument("electric-guitar");
    EXPECT_EQ(guitar.strings.size(), 6u);
    EXPECT_NEAR(guitar.strings[5].tension_n, 16.2 * 4.4482216152605, 1e-9);
}

TEST(StringNeck, WhatALuthierMeasuresIsWhatTheFileSays) {
    const Instrument bass = load_instrument("jazz-bass");
    const StringNeck e(bass, 0);
    EXPECT_NEAR(e.gap(1), 0.75e-3, 1e-15);
    EXPECT_NEAR(e.gap(12), 2.7e-3, 1e-15);
    const Instrument guitar = load_instrument("electric-guitar");
    const StringNeck low(guitar, 0);
    EXPECT_NEAR(low.relief_gap(8), 0.010 * 0.0254, 1e-15);  // read under the first string, crown included
    EXPECT_NEAR(low.gap(17), 4.0 / 64.0 * 0.0254, 1e-15);
    EXPECT_NEAR(low.gap(1), 0.020 * 0.0254, 1e-15);
    // The saddle height is what gives that action: the string line passes through it.
    EXPECT_NEAR(low.string_height(low.length()), low.saddle_height(), 1e-15);
}

// The single-string built-in is the bass-neck case's neck: the same fret tops below the
// open string on the same grid.
TEST(StringNeck, TheSingleStringBuiltInIsTheBassNeckCase) {
    const Case c = load_case("bass-neck");
    const StringNeck neck(load_instrument("bass-neck"), 0);
    const Grid grid{c.string.length_m, c.mode_count()};
    const std::vector<double> g = neck.note_obstacle(0, grid);
    // (the case's crowns are exact points: on the grid, each on its nearest grid point)
    const std::vector<double> on_grid = c.obstacle_on_grid();
    for (std::size_t n = 1; n <= neck.fret_count(); ++n) {
        const std::size_t i = nearest_grid_point(grid, neck.fret_x(n));
        EXPECT_NEAR(g[i], on_grid[i], 1e-15) << "fret " << n;
    }
    // Between the frets the board is straight from fret to fret here (the case's relief curve
    // is linear between its points): within 2 micrometres, 1.2 mm below the fret tops. (Past
    // the board the body is parallel to the fret plane here, to the string there.)
    for (std::size_t i = 0; grid.x(i) <= neck.board_end(); ++i)
        if (std::isfinite(on_grid[i])) {
            EXPECT_NEAR(g[i], on_grid[i], 2e-6) << "x = " << grid.x(i);
        }
}

// A fret entered through an instrument file acts where the same fret from a case file does:
// the bench's note cases carry the bass-neck instrument's frets as exact points at
// x_n = S (1 - 2^(-n/12)) (from the stop, x_n - x_k), those of the bass-neck case, not on
// the grid's nearest points; the finger of the finger model stands where the case's
// `fret = k` puts it.
TEST(SetupNotes, AnInstrumentsFretsActAtTheCaseFilesExactPositions) {
    const Case c = load_case("bass-neck");
    const Instrument bass = load_instrument("bass-neck");
    const NoteMaker maker(bass, 0);
    const Case& open = maker.open_string();
    ASSERT_EQ(c.point_obstacles.size(), 20u);
    ASSERT_EQ(open.point_obstacles.size(), c.point_obstacles.size());
    std::size_t off_grid = 0;
    for (std::size_t n = 0; n < open.point_obstacles.size(); ++n) {
        const PointObstacle& p = open.point_obstacles[n];
        EXPECT_NEAR(p.x_m, c.point_obstacles[n].x_m, 1e-12) << "fret " << n + 1;
        EXPECT_NEAR(p.height_m, c.point_obstacles[n].height_m, 1e-15) << "fret " << n + 1;
        EXPECT_EQ(p.weight_m, open.grid_step());
        EXPECT_EQ(open.fret_positions_m[n], p.x_m);
        off_grid += std::abs(std::remainder(p.x_m, open.grid_step())) > 1e-6 * open.grid_step();
    }
    EXPECT_GE(off_grid, 19u);  // (a fret may fall on a grid point by chance)
    // The grid point nearest a fret keeps the board's height, as the case's does.
    const std::size_t near12 = static_cast<std::size_t>(std::lround(open.point_obstacles[11].x_m / open.grid_step())) - 1;
    EXPECT_LT(open.obstacle_height_m[near12], open.point_obstacles[11].height_m - 1e-3);
    for (std::size_t k : {1u, 5u, 12u, 19u}) {
        const Case& note = maker.stopped(k);
        const std::vector<double> expected = maker.fret_positions(k, false);
        ASSERT_EQ(note.point_obstacles.size(), expected.size()) << "note " << k;
        for (std::size_t i = 0; i < expected.size(); ++i) {
            EXPECT_NEAR(note.point_obstacles[i].x_m, c.point_obstacles[k + i].x_m - c.point_obstacles[k - 1].x_m, 1e-12)
                << "note " << k << ", fret " << k + 1 + i;
            EXPECT_EQ(note.point_obstacles[i].x_m, expected[i]);
            EXPECT_EQ(note.fret_positions_m[i], expected[i]);
        }
        const Case fingered = maker.fingered(k, parse_attacks("medium", bass.attack).front(), {});
        Case fretted = c;
        fretted.add_fret_finger(k, "fret");
        ASSERT_FALSE(fingered.fingers.empty());
        EXPECT_NEAR(fingered.fingers.front().position_m, fretted.fingers.back().position_m, 1e-12) << "note " << k;
        EXPECT_NEAR(fingered.fingers.front().width_m, fretted.fingers.back().width_m, 1e-12) << "note " << k;
    }
}

// The note stopped at fret k sees every fret top beyond k where the whole neck has it,
// measured from its own string at rest (from fret k's top to the saddle).
TEST(StringNeck, StoppedNotesSeeTheFretTopsOfTheWholeNeck) {
    Instrument bass = load_instrument("jazz-bass");
    bass.neck.fret_offset_m[9] = 0.05e-3;
    const StringNeck neck(bass, 1);
    for (std::size_t k : {0u, 3u, 8u, 12u, 19u}) {
        const double sounding = neck.length() - neck.fret_x(k);
        const Grid grid{sounding, static_cast<std::size_t>(std::lround(sounding / 1e-3)) - 1};
        const std::vector<double> g = neck.note_obstacle(k, grid);
        for (std::size_t n = k + 1; n <= neck.fret_count(); ++n) {
            const double line = neck.fret_top(k == 0 ? 0 : k) +
                                (neck.saddle_height() - neck.fret_top(k)) * (neck.fret_x(n) - neck.fret_x(k)) / sounding;
            const double expected = k == 0 ? neck.fret_top(n) - neck.string_height(neck.fret_x(n)) : neck.fret_top(n) - line;
            EXPECT_NEAR(g[nearest_grid_point(grid, neck.fret_x(n) - neck.fret_x(k))], expected, 1e-15)
                << "note " << k << ", fret " << n;
            EXPECT_GT(neck.clearance(k, n), 0.0);
        }
        EXPECT_FALSE(neck.rests_on(k).has_value());
    }
    EXPECT_NEAR(neck.fret_top(9) - neck.fret_line(9), 0.05e-3, 1e-15);
}

// Strings fanning out over a cylinder see a crowned fret line: the outer ones by about
// (dy/dx)^2 x (x_N - x) / (2 R), the middle one (on the neck's centre line) not at all.
TEST(StringNeck, TheRadiusCrownsTheOuterStrings) {
    Instrument g = load_instrument("electric-guitar");
    g.neck.relief = {};
    g.neck.fret_offset_m.clear();
    for (auto& s : g.strings) s.bridge = {StringEnd::Form::gap_over_fret, 2e-3, 12};
    g.strings.resize(5);  // an odd count: the third string runs down the middle
    g.neck.relief_pull_n.reset();  // (and one string fewer pulling does not bow this neck)
    const double radius = *g.neck.radius_m;
    const StringNeck middle(g, 2), outer(g, 0);
    const std::size_t n = 10;
    EXPECT_NEAR(middle.fret_line(n), 0.0, 1e-18);
    const double slope = 0.5 * (g.neck.bridge_spacing_m - g.neck.nut_width_m) / outer.length();
    const double x = outer.fret_x(n), last = outer.fret_x(outer.fret_count());
    const auto drop = [&](double at) {
        const double y = -0.5 * (g.neck.nut_width_m + (g.neck.bridge_spacing_m - g.neck.nut_width_m) * at / outer.length());
        return radius - std::sqrt(radius * radius - y * y);
    };
    EXPECT_NEAR(outer.fret_line(n), drop(0.0) + (drop(last) - drop(0.0)) * x / last - drop(x), 1e-15);
    EXPECT_NEAR(outer.fret_line(n), slope * slope * x * (last - x) / (2.0 * radius), 0.02 * outer.fret_line(n));
    EXPECT_GT(outer.fret_line(n), 0.0);
}

TEST(StringNeck, MultiscaleFretsFallOnEachStringsScale) {
    Instrument bass = load_instrument("jazz-bass");
    bass.strings[0].scale_length_m = 0.889;  // 35 in
    const StringNeck e(bass, 0), g(bass, 3);
    EXPECT_NEAR(e.fret_x(12), 0.889 / 2.0, 1e-15);
    EXPECT_NEAR(g.fret_x(12), 0.863 / 2.0, 1e-15);
}

using testing::expect_instrument_refused;
using testing::replaced;

TEST(InstrumentFile, BadValuesAreRefusedNamingTheKeyAndItsRange) {
    const std::string base(*find_builtin_file("instruments/jazz-bass.toml"));
    EXPECT_NO_THROW(parse_instrument(base, "test.toml", DataSource::builtin()));
    expect_instrument_refused(replaced(base, "fret_height = \"1.2 mm\"", "fret_height = \"12 mm\""), "neck.fret_height", "(0, 5] mm");
    expect_instrument_refused(replaced(base, "fret_height = \"1.2 mm\"", "fret_height = 1.2"), "neck.fret_height", "unit");
    expect_instrument_refused(replaced(base, "frets = 20", "frets = 99"), "neck.frets", "[1, 24]");
    expect_instrument_refused(replaced(base, "nut = \"0.75 mm\"", "nut = \"-0.7 mm\""), "string[0].nut", "[0.01, 5] mm");
    expect_instrument_refused(replaced(base, "action12 = \"2.7 mm\"", "action12 = \"27 mm\""), "string[0].action12", "[0.01, 10] mm");
    expect_instrument_refused(replaced(base, "pitch = \"E1\"", "pitch = \"H1\""), "string[0].pitch");
    const std::string with_attack = base + "\n[attack]\n";
    expect_instrument_refused(with_attack + "soft = \"5 mm\"\n", "attack.medium", "must grow: soft (5 mm) < medium");
    // Attacks out of their ranges: a finger pulling away from the board, a slap faster than a hand.
    expect_instrument_refused(with_attack + "angle = -20\n", "attack.angle", "[0, 90] degrees");
    expect_instrument_refused(with_attack + "pick_angle = 120\n", "attack.pick_angle", "[0, 90] degrees");
    expect_instrument_refused(with_attack + "slap = \"25 m/s\"\n", "attack.slap", "(0, 10] m/s");
    expect_instrument_refused(with_attack + "thumb_mass = \"2 kg\"\n", "attack.thumb_mass", "(0, 200] g");
    expect_instrument_refused(with_attack + "angle_spread = 60\n", "attack.angle_spread", "[0, 45] degrees");
    expect_instrument_refused(with_attack + "style = \"banjo\"\n", "attack.style", "\"bass\" or \"guitar\"");
    expect_instrument_refused(with_attack + "hard = \"11 mm\"\n", "attack.hard", "(0, 10] mm");
    expect_instrument_refused(replaced(base, "[[string]]\nname = \"A\"", "[[string]]\nname = \"E\""), "string[1].name");
    expect_instrument_refused(replaced(base, "set = \"daddario-exl170\"", "set = \"unknown\""), "strings.set");
    expect_instrument_refused(replaced(base, "board_end = \"600 mm\"", "board_end = \"600 mm\"\nboard_edn = 1"), "neck.board_edn");
    expect_instrument_refused(replaced(base, "[neck]", "[obstacle]\ntype = \"none\"\n[neck]"), "case file");
    // A relief so deep that the open E string would lie on a fret.
    Instrument bass = parse_instrument(replaced(base, "action12 = \"2.7 mm\"", "action12 = \"0.2 mm\""), "t.toml",
                                       DataSource::builtin());
    try {
        StringNeck(bass, 0);
        ADD_FAILURE() << "an open string lying on a fret was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("string[0]"), std::string::npos) << e.what();
    }
}

// The name becomes the studio's folder, studio-NAME in the current folder: one plain path
// component, whatever the file says.
TEST(InstrumentFile, TheNameIsOnePlainPathComponent) {
    const std::string base(*find_builtin_file("instruments/jazz-bass.toml"));
    for (const char* bad : {"x/../../../../victim-home", "", "/", "..", ".", ".hidden", "a..b", "<script>", " lead",
                            "a\\b", "tab\there", "caf\u00e9"}) {
        SCOPED_TRACE(bad);
        expect_instrument_refused(replaced(base, "name = \"jazz-bass\"", "name = \"" + std::string(bad) + "\""), "name = \"",
                       "letters (a-z, A-Z), digits");
    }
    expect_instrument_refused(replaced(base, "name = \"jazz-bass\"", "name = \"" + std::string(65, 'a') + "\""), "name", "1 to 64");
    for (const std::string& good : std::vector<std::string>{"jazz-bass", "My Bass 2.0", "fender_jb-1962", std::string(64, 'b')}) {
        const Instrument i =
            parse_instrument(replaced(base, "name = \"jazz-bass\"", "name = \"" + good + "\""), "t.toml", DataSource::builtin());
        EXPECT_EQ(i.name, good);
    }
}

// What an instrument file takes, a what-if takes (src/setup/WhatIf.cpp), and the other way
// round; the messages show the value as written.
TEST(InstrumentFile, RangesAreTheWhatIfsAndMessagesShowTheValueGiven) {
    const std::string base(*find_builtin_file("instruments/jazz-bass.toml"));
    expect_instrument_refused(replaced(base, "action12 = \"2.7 mm\"", "action12 = \"1e-320 mm\""), "string[0].action12",
                   "[0.01, 10] mm");
    expect_instrument_refused(replaced(base, "nut = \"0.75 mm\"", "nut = \"0.001 mm\""), "string[0].nut", "[0.01, 5] mm");
    const Instrument bass = parse_instrument(base, "t.toml", DataSource::builtin());
    SetupChange tiny_action, tiny_nut, low_nut;
    tiny_action.action_m = {{"E", 12, 1e-323}};
    tiny_nut.nut_m = {{"E", 1e-6}};
    low_nut.nut_m = {{"E", 1e-5}};
    for (const auto& [change, key] : std::vector<std::pair<SetupChange, std::string>>{{tiny_action, "--action12 E"},
                                                                                      {tiny_nut, "--nut E"}}) {
        try {
            apply_change(bass, change);
            ADD_FAILURE() << key << " accepted";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
        }
    }
    // The smallest value each takes is the same.
    const Instrument low = parse_instrument(replaced(base, "nut = \"0.75 mm\"", "nut = \"0.01 mm\""), "t.toml",
                                            DataSource::builtin());
    EXPECT_NO_THROW(apply_change(bass, low_nut));
    EXPECT_DOUBLE_EQ(low.strings[0].nut.value_m, 1e-5);
    // An integer past 2^53 is shown as written, not as 0.
    expect_instrument_refused(replaced(base, "nut = \"0.75 mm\"", "nut = 9223372036854775807"), "string[0].nut = 9223372036854775807",
                   "say its unit");
    // Too few frets to measure relief is said as such, not as an empty range [2, 0].
    const std::string curve =
        R"(curve = [["178 mm", "0.41 mm"], ["319 mm", "0.595 mm"], ["431.5 mm", "0.517 mm"], ["520.5 mm", "0.228 mm"]])";
    const std::string short_neck = replaced(replaced(base, "frets = 20", "frets = 1"), curve, "gap = \"0.3 mm\"");
    try {
        parse_instrument(short_neck, "t.toml", DataSource::builtin());
        ADD_FAILURE() << "a one-fret neck with a relief gap was accepted";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_EQ(what.find("[2, 0]"), std::string::npos) << what;
        EXPECT_NE(what.find("at least 3 frets (neck.frets = 1)"), std::string::npos) << what;
    }
}

TEST(InstrumentFile, AMeasuredProfileIsAcceptedAsTheNeckUnderAString) {
    const std::string base(*find_builtin_file("instruments/bass-neck.toml"));
    std::string text = replaced(base, "nut_height = \"0.35 mm\"\naction = \"2.34 mm\"\naction_fret = 20",
                                "profile = \"data/bass_fretted_obstacle.csv\"");
    const Instrument measured = parse_instrument(text, "t.toml", DataSource::builtin());
    const StringNeck neck(measured, 0);
    EXPECT_TRUE(neck.measured_profile());
    // On its own grid the open string sees the measured profile itself.
    const Case pop = load_case("bass-pop");
    const std::vector<double> g = neck.note_obstacle(0, Grid{pop.string.length_m, pop.mode_count()});
    for (std::size_t i = 0; i < g.size(); ++i) EXPECT_NEAR(g[i], pop.obstacle_height_m[i], 1e-15) << i;
}

// docs/instrument-format.md against the reader: every key the reader looks up while reading
// the built-in instruments has a row in one of the page's tables (or is a table's heading).
TEST(InstrumentFile, EveryKeyTheReaderLooksUpIsDocumented) {
    std::ifstream in(std::string(FRETBUZZ_SOURCE_DIR) + "/docs/instrument-format.md");
    std::ostringstream text;
    text << in.rdbuf();
    const std::string doc = text.str();
    std::set<std::string> documented;
    const std::regex row(R"(\n\| `([A-Za-z0-9_.]+)` \|)"), heading(R"(\n## [^\n]*)"), table(R"(\[+([a-z.]+)\]+)");
    for (auto it = std::sregex_iterator(doc.begin(), doc.end(), row); it != std::sregex_iterator(); ++it)
        documented.insert((*it)[1].str());
    for (auto h = std::sregex_iterator(doc.begin(), doc.end(), heading); h != std::sregex_iterator(); ++h) {
        const std::string line = h->str();
        for (auto it = std::sregex_iterator(line.begin(), line.end(), table); it != std::sregex_iterator(); ++it)
            documented.insert((*it)[1].str());
    }
    std::set<std::string> looked_up;
    for (const auto& info : builtin_instruments()) {
        const std::string file = "instruments/" + info.name + ".toml";
        const std::set<std::string> keys =
            instrument_keys_looked_up(*find_builtin_file(file), file, DataSource::builtin());
        looked_up.insert(keys.begin(), keys.end());
    }
    ASSERT_GT(looked_up.size(), 40u);
    for (const std::string& key : looked_up) {
        if (key == "obstacle" || key == "excitation") continue;  // only asked to tell a case file apart
        EXPECT_TRUE(documented.contains(key)) << key << " is not in docs/instrument-format.md";
    }
}

// The instrument file of docs/setup.md's tutorial reads (and gives back what it says).
TEST(InstrumentFile, TheTutorialsInstrumentReads) {
    std::ifstream in(std::string(FRETBUZZ_SOURCE_DIR) + "/docs/setup.md");
    std::ostringstream text;
    text << in.rdbuf();
    const std::string doc = text.str();
    std::smatch block;
    const std::regex marker(R"(<!-- instrument: my-bass -->\s*```toml\n([\s\S]*?)```)");
    ASSERT_TRUE(std::regex_search(doc, block, marker));
    const Instrument bass = parse_instrument(block[1].str(), "my-bass.toml", DataSource::builtin());
    ASSERT_EQ(bass.strings.size(), 4u);
    const StringNeck e(bass, 0);
    EXPECT_NEAR(e.gap(12), 7.0 / 64.0 * 0.0254, 1e-15);
    EXPECT_NEAR(e.gap(1), 0.024 * 0.0254, 1e-15);
    EXPECT_NEAR(e.relief_gap(8), 0.012 * 0.0254, 1e-15);
}

// A scan of the fret tops (fret, string, height above the straightedge on fret 1 and the last
// fret) in place of the relief: the scan of a neck gives back that neck, gap for gap.
TEST(InstrumentFile, AFretScanGivesBackTheNeckItWasTakenFrom) {
    const Instrument bass = load_instrument("jazz-bass");
    const StringNeck e(bass, 0);
    const std::size_t last = e.fret_count();
    const auto path = std::filesystem::temp_directory_path() / ("fretbuzz-scan-" + std::to_string(::getpid()));
    std::filesystem::create_directories(path);
    {
        std::ofstream csv(path / "scan.csv");
        csv.precision(17);
        csv << "fret,string,height_mm\n";
        for (std::size_t n = 1; n <= last; ++n) {
            const double chord = e.fret_top(1) + (e.fret_top(last) - e.fret_top(1)) * (e.fret_x(n) - e.fret_x(1)) /
                                                     (e.fret_x(last) - e.fret_x(1));
            csv << n << ",1," << (e.fret_top(n) - chord) * 1e3 << "\n";
        }
        std::string text = bass.source_text;
        const std::string relief = text.substr(text.find("[neck.relief]"), text.find("[strings]") - text.find("[neck.relief]"));
        text.replace(text.find(relief), relief.size(), "");
        text.replace(text.find("frets = 20"), 10, "frets = 20\nscan = \"scan.csv\"");
        std::ofstream(path / "scanned.toml") << text;
    }
    const Instrument scanned = load_instrument((path / "scanned.toml").string());
    std::filesystem::remove_all(path);
    const StringNeck s(scanned, 0);
    for (std::size_t n = 1; n <= last; ++n) EXPECT_NEAR(s.gap(n), e.gap(n), 1e-12) << "fret " << n;
    EXPECT_NEAR(s.relief_gap(8), e.relief_gap(8), 1e-12);
    // The other strings, not scanned, keep the neck's relief (none here: the curve was removed).
    EXPECT_NEAR(StringNeck(scanned, 1).relief_gap(8), 0.0, 1e-15);
}

// A fanned neck: each string's frets on its own scale, its nut placed so that the
// perpendicular fret lines up across the strings.
TEST(StringNeck, AFannedNeckLinesUpItsPerpendicularFret) {
    std::string text(*find_builtin_file("instruments/jazz-bass.toml"));
    text.replace(text.find("scale = \"863 mm\""), 16, "scale = [\"35.5 in\", \"34 in\"]\nperpendicular_fret = 7");
    const Instrument fan = parse_instrument(text, "fan.toml", DataSource::builtin());
    const std::vector<StringGeometry> g = describe_geometry(fan);
    ASSERT_EQ(g.size(), 4u);
    EXPECT_NEAR(g[0].scale_length_m, 35.5 * 0.0254, 1e-15);
    EXPECT_NEAR(g[3].scale_length_m, 34 * 0.0254, 1e-15);
    EXPECT_NEAR(g[1].scale_length_m, (2 * 35.5 + 34) / 3 * 0.0254, 1e-12);
    for (std::size_t s = 0; s < 4; ++s)  // fret 7 at one place along the neck
        EXPECT_NEAR(g[s].nut_axial_m + g[s].fret_x_m[7], g[0].nut_axial_m + g[0].fret_x_m[7], 1e-12);
    EXPECT_GT(g[3].nut_axial_m, g[0].nut_axial_m);  // the short string's nut lies further along
}

}  // namespace
}  // namespace fretbuzz
