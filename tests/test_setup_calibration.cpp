// The player's own touch (setup/Calibration): a report of the notes a player hears buzz or
// ring clean is explained by one attack scale, or said to be explained by none.
//  - round trip: a report made from the bench's own verdicts at 1.4 times the medium pluck is
//    calibrated back to a scale within 15 % of 1.4;
//  - a report no scale explains (a note heard clean that needs less margin than one heard
//    buzzing; the same note heard both ways) says so and names the notes;
//  - bad rows and bad --player files are refused naming the column, the row or the key and the
//    range (InputError, exit 2), with nothing written.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "SetupTestSupport.hpp"
#include "TestSupport.hpp"
#include "fretbuzz/setup/BuzzMap.hpp"
#include "fretbuzz/setup/Calibration.hpp"
#include "fretbuzz/setup/NoteJudge.hpp"

namespace fretbuzz {
namespace {

using testing::run_cli;
using testing::ScratchDir;

// The quick bass with ensembles large enough that a note can be called clean (25 plucks none
// of which buzzes): the report's "clean" is then the bench's.
Instrument calibration_bass() { return testing::quick_bass(plucks_for_clean(), 0.1); }

// Every note of frets 0-16 on every string: their margins differ from fret to fret and string
// to string, so some lie close on either side of a scale in the searched range.
std::vector<MapNote> spread_notes() {
    std::vector<MapNote> notes;
    for (std::size_t string = 0; string < 4; ++string)
        for (std::size_t fret = 0; fret <= 16; ++fret) notes.push_back({string, fret});
    return notes;
}

std::string report_of(const Instrument& bass, const std::vector<NoteVerdict>& verdicts) {
    std::string text = "string,fret,heard,strength\n";
    for (const NoteVerdict& v : verdicts)
        text += bass.strings[v.string].name + "," + std::to_string(v.fret) + "," +
                (v.verdict == "clean" ? "clean" : "buzz") + ",medium\n";
    return text;
}

void expect_refused(const std::string& text, const std::string& key, const std::string& allowed) {
    const Instrument bass = testing::quick_bass();
    try {
        parse_player_report(text, "report.csv", bass);
        ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("--calibrate"), std::string::npos) << what;
        EXPECT_NE(what.find(key), std::string::npos) << what;
        EXPECT_NE(what.find(allowed), std::string::npos) << what;
    }
}

TEST(SetupCalibration, ARoundTripFindsTheScaleTheReportWasHeardAt) {
    const Instrument bass = calibration_bass();
    constexpr double kHeardAt = 1.4;
    // What the player hears: the bench's verdicts at 1.4 times the medium pluck (marginal, some of
    // the plucks buzzing, is heard as a buzz).
    MapRequest heard;
    heard.notes = spread_notes();
    heard.attacks = parse_attacks("medium", bass.attack);
    heard.attacks.front().size *= kHeardAt;
    heard.clean_up_to = false;
    const BuzzMapResult played = play_map(bass, heard);
    const std::string report = report_of(bass, played.notes);
    std::cout << report;
    const Calibration c = calibrate_attack(bass, parse_player_report(report, "round-trip.csv", bass));
    for (const CalibratedNote& n : c.notes)
        std::cout << n.heard.string_name << n.heard.fret << " heard " << (n.heard.buzz ? "buzz" : "clean")
                  << ", clean up to " << n.clean_up_to << "\n";
    std::cout << calibration_text(c);
    ASSERT_TRUE(std::isfinite(c.attack_scale));
    // The interval holds a scale within 15 % of 1.4, and the scale given is one.
    EXPECT_LE(c.low, kHeardAt * 1.15);
    EXPECT_GE(c.high, kHeardAt / 1.15);
    EXPECT_NEAR(c.attack_scale, kHeardAt, 0.15 * kHeardAt);
    EXPECT_GT(c.attack_scale, c.low);
    EXPECT_LE(c.attack_scale, c.high);
    // At most a row or two disagrees (a member whose buzz is not monotone in the size): the
    // verdicts at 1.4x and the margins at 1x are the same plucks.
    EXPECT_LE(c.disagreements, 1u) << c.statement;
    // Both kinds were heard, so the interval is bounded both ways.
    EXPECT_TRUE(c.low_bounded) << c.statement;
    EXPECT_FALSE(c.high_at_least) << c.statement;

    // The JSON holds the scale, its interval and every note.
    const auto doc = nlohmann::json::parse(calibration_json(c, bass, "round-trip.csv"));
    EXPECT_DOUBLE_EQ(doc["attack_scale"].get<double>(), c.attack_scale);
    EXPECT_DOUBLE_EQ(doc["attack_scale_low"].get<double>(), c.low);
    EXPECT_DOUBLE_EQ(doc["attack_scale_high"].get<double>(), c.high);
    EXPECT_EQ(doc["notes"].size(), spread_notes().size());
    EXPECT_EQ(doc["disagreeing"].size(), c.disagreements);

    // Applied (--player), the scale multiplies the attack's size.
    std::vector<Attack> attacks = parse_attacks("medium", bass.attack);
    scale_attacks(attacks, c.attack_scale);
    EXPECT_NEAR(attacks.front().size, c.attack_scale * bass.attack.medium_m, 1e-15);
}

TEST(SetupCalibration, AReportNoScaleExplainsSaysSo) {
    const Instrument bass = calibration_bass();
    // Two notes whose margins differ: heard the wrong way round (the one with less margin clean,
    // the one with more buzzing), no scale explains both.
    MapRequest request;
    request.notes = {{0, 1}, {0, 12}, {3, 15}};
    request.attacks = parse_attacks("medium", bass.attack);
    const BuzzMapResult map = play_map(bass, request);
    const NoteVerdict* least = &map.notes.front();
    const NoteVerdict* most = &map.notes.front();
    for (const NoteVerdict& v : map.notes) {
        if (v.clean_up_to < least->clean_up_to) least = &v;
        if (v.clean_up_to > most->clean_up_to) most = &v;
    }
    ASSERT_LT(least->clean_up_to, most->clean_up_to);
    const std::string report = "string,fret,heard\n" + least->string_name + "," + std::to_string(least->fret) +
                               ",clean\n" + most->string_name + "," + std::to_string(most->fret) + ",buzz\n";
    const Calibration c = calibrate_attack(bass, parse_player_report(report, "contrary.csv", bass));
    EXPECT_FALSE(c.explained);
    EXPECT_EQ(c.disagreements, 1u);
    EXPECT_NE(c.statement.find("No scale explains the report"), std::string::npos) << c.statement;
    const auto doc = nlohmann::json::parse(calibration_json(c, bass, "contrary.csv"));
    EXPECT_FALSE(doc["explained"].get<bool>());
    EXPECT_EQ(doc["disagreeing"].size(), 1u);

    // The fit alone: one note heard both clean and buzzing disagrees at every scale.
    CalibratedNote clean, buzz;
    clean.heard.string_name = buzz.heard.string_name = "E";
    clean.heard.fret = buzz.heard.fret = 7;
    clean.heard.row = 1;
    buzz.heard.row = 2;
    buzz.heard.buzz = true;
    clean.status = buzz.status = "ok";
    clean.clean_up_to = buzz.clean_up_to = 1.2;
    const Calibration twice = fit_attack_scale({clean, buzz});
    EXPECT_FALSE(twice.explained);
    EXPECT_EQ(twice.disagreements, 1u);
    // A note that frets out, heard clean, buzzes at every scale: it is named.
    CalibratedNote out = clean;
    out.status = "frets out";
    out.clean_up_to = 0.0;
    const Calibration fretted = fit_attack_scale({out, buzz});
    EXPECT_FALSE(fretted.explained);
    EXPECT_NE(fretted.statement.find("frets out"), std::string::npos) << fretted.statement;
    // Explained, the interval runs from the largest buzzing margin to the smallest clean one.
    CalibratedNote low = buzz, high = clean;
    low.clean_up_to = 0.8;
    high.clean_up_to = 1.6;
    const Calibration fits = fit_attack_scale({low, high});
    EXPECT_TRUE(fits.explained);
    EXPECT_DOUBLE_EQ(fits.low, 0.8);
    EXPECT_DOUBLE_EQ(fits.high, 1.6);
    EXPECT_GT(fits.attack_scale, 0.8);
    EXPECT_LT(fits.attack_scale, 1.6);
}

TEST(SetupCalibration, BadRowsAreRefusedNamingTheColumnAndRow) {
    expect_refused("string,fret,heard\nX,3,buzz\n", "column string", "its strings: E, A, D, G");
    expect_refused("string,fret,heard\nE,3,buzz\nE,99,clean\n", "row 2", "frets are 0 (open) to");
    expect_refused("string,fret,heard\nE,-1,clean\n", "column fret", "frets are 0 (open) to");
    expect_refused("string,fret,heard\nE,3,loud\n", "column heard", "must be buzz or clean");
    expect_refused("string,fret,heard,strength\nE,3,buzz,thunder\n", "column strength", "soft, medium, hard");
    expect_refused("string,fret,heard\n", "holds no rows", "string, fret, heard");
    expect_refused("", "holds no rows", "string, fret, heard");
    expect_refused("string,fret\nE,3\n", "no column heard", "string, fret, heard");
    expect_refused("string,fret,heard,strenght\nE,3,buzz,soft\n", "\"strenght\"", "string, fret, heard");
    expect_refused("string,fret,heard\nE,3,buzz,soft\n", "row 1", "the header names 3 columns");
    expect_refused("string,fret,heard\nE,3\n", "row 1 (line 2), column heard", "must be buzz or clean");
    std::string many = "string,fret,heard\n";
    for (std::size_t k = 0; k <= kMaxReportRows; ++k) many += "E,3,buzz\n";
    expect_refused(many, "row 10001", "at most 10000 rows");
    // A good report reads whatever its column order, blanks and case, medium by default.
    const Instrument bass = testing::quick_bass();
    const auto rows = parse_player_report("\xEF\xBB\xBF# my bass\nHeard, Fret, String\nBuzz, 3, E\n\"clean\",12,G\n",
                                          "ok.csv", bass);
    ASSERT_EQ(rows.size(), 2u);
    EXPECT_TRUE(rows[0].buzz);
    EXPECT_EQ(rows[0].fret, 3u);
    EXPECT_EQ(rows[1].string, 3u);
    EXPECT_EQ(rows[1].attack.label, "medium");
    EXPECT_DOUBLE_EQ(rows[1].attack.size, bass.attack.medium_m);
}

// The report of docs/setup.md ("Calibrating the attack to your own ears") reads as it says.
TEST(SetupCalibration, TheTutorialsReportReads) {
    std::ifstream in(std::string(FRETBUZZ_SOURCE_DIR) + "/docs/setup.md");
    std::stringstream text;
    text << in.rdbuf();
    const std::string doc = text.str();
    const std::size_t section = doc.find("### Calibrating the attack to your own ears");
    ASSERT_NE(section, std::string::npos);
    const std::size_t start = doc.find("```csv\n", section);
    ASSERT_NE(start, std::string::npos);
    const std::size_t end = doc.find("```", start + 7);
    const Instrument bass = testing::quick_bass();
    const auto rows = parse_player_report(doc.substr(start + 7, end - start - 7), "docs/setup.md", bass);
    ASSERT_EQ(rows.size(), 4u);
    EXPECT_FALSE(rows[0].buzz);
    EXPECT_TRUE(rows[1].buzz);
    EXPECT_EQ(rows[2].attack.label, "hard");
    EXPECT_EQ(rows[3].attack.label, "medium");  // left out: medium
}

TEST(SetupCalibration, APlayerFileIsCheckedBeforeItIsUsed) {
    ScratchDir dir("player");
    const auto write = [&](const std::string& name, const std::string& text) {
        std::ofstream(dir.path() / name) << text;
        return dir.path() / name;
    };
    const auto refused = [](const std::filesystem::path& path, const std::string& part) {
        try {
            read_player_touch(path);
            ADD_FAILURE() << "accepted " << path;
        } catch (const InputError& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find("--player"), std::string::npos) << what;
            EXPECT_NE(what.find(part), std::string::npos) << what;
            EXPECT_NE(what.find("(0, 10]"), std::string::npos) << what;
        }
    };
    refused(write("zero.json", R"({"attack_scale": 0})"), "attack_scale = 0 is out of range");
    refused(write("big.json", R"({"attack_scale": 12.5})"), "attack_scale = 12.5 is out of range");
    refused(write("none.json", R"({"attack_scale": null})"), "not a number");
    refused(write("missing.json", R"({"scale": 1.2})"), "holds no attack_scale");
    refused(write("text.json", "not json"), "is not JSON");
    refused(dir.path(), "is not a regular file");
    refused(dir.path() / "absent.json", "no such file");
    refused(write("huge.json", std::string((1u << 20) + 1, ' ')), "larger than 1 MiB");
    const PlayerTouch touch = read_player_touch(write("good.json", R"({"attack_scale": 1.37, "notes": []})"));
    EXPECT_DOUBLE_EQ(touch.attack_scale, 1.37);
    std::vector<Attack> attacks = parse_attacks("soft,hard,slap", testing::quick_bass().attack);
    const std::vector<Attack> before = attacks;
    scale_attacks(attacks, touch.attack_scale);
    for (std::size_t k = 0; k < attacks.size(); ++k) EXPECT_DOUBLE_EQ(attacks[k].size, 1.37 * before[k].size);
}

// Through the program: a tiny calibration writes calibration.json and a map played with it says
// so; a bad report row and a bad --player exit 2 naming them, writing nothing.
TEST(SetupCalibration, TheCommandCalibratesAndAppliesIt) {
    ScratchDir dir("calibrate");
    const std::string quick = " --ensemble 2 --fs 500kHz --duration 0.08 --quiet";
    std::ofstream(dir.path() / "report.csv") << "string,fret,heard,strength\nG,19,buzz,hard\nG,20,buzz,medium\n";
    const std::string out = (dir.path() / "cal").string();
    const auto r = run_cli("setup jazz-bass --calibrate " + (dir.path() / "report.csv").string() + " --out " + out + quick);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("calibration:"), std::string::npos) << r.output;
    std::ifstream in(dir.path() / "cal" / "calibration.json");
    std::stringstream text;
    text << in.rdbuf();
    const auto doc = nlohmann::json::parse(text.str());
    for (const char* key : {"attack_scale", "attack_scale_low", "attack_scale_high", "notes", "disagreeing", "statement"})
        EXPECT_TRUE(doc.contains(key)) << key;
    ASSERT_EQ(doc["notes"].size(), 2u);
    EXPECT_TRUE(doc["notes"][0].contains("clean_up_to"));
    EXPECT_TRUE(doc["notes"][0].contains("agrees"));

    // Applied: map.json names the file and the scale, and the attacks played are scaled by it.
    std::ofstream(dir.path() / "touch.json") << R"({"attack_scale": 1.5})";
    const std::string map = (dir.path() / "map").string();
    const auto m = run_cli("setup jazz-bass --strings G --frets 20 --strength medium --player " +
                           (dir.path() / "touch.json").string() + " --out " + map + quick);
    ASSERT_EQ(m.exit_code, 0) << m.output;
    std::ifstream map_in(dir.path() / "map" / "map.json");
    std::stringstream map_text;
    map_text << map_in.rdbuf();
    const auto map_doc = nlohmann::json::parse(map_text.str());
    EXPECT_DOUBLE_EQ(map_doc["calibration"]["attack_scale"].get<double>(), 1.5);
    EXPECT_NE(map_doc["calibration"]["file"].get<std::string>().find("touch.json"), std::string::npos);
    EXPECT_NEAR(map_doc["attacks"][0]["size"].get<double>(), 1.5 * testing::quick_bass().attack.medium_m * 1e3, 1e-9);

    std::ofstream(dir.path() / "bad.csv") << "string,fret,heard\nG,7,sometimes\n";
    const auto bad = run_cli("setup jazz-bass --calibrate " + (dir.path() / "bad.csv").string() + " --out " +
                             (dir.path() / "bad").string() + quick);
    EXPECT_EQ(bad.exit_code, 2) << bad.output;
    EXPECT_NE(bad.output.find("column heard"), std::string::npos) << bad.output;
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "bad"));
    std::ofstream(dir.path() / "wild.json") << R"({"attack_scale": 40})";
    const auto wild = run_cli("setup jazz-bass --player " + (dir.path() / "wild.json").string() + " --out " +
                              (dir.path() / "wild").string() + quick);
    EXPECT_EQ(wild.exit_code, 2) << wild.output;
    EXPECT_NE(wild.output.find("--player"), std::string::npos) << wild.output;
    EXPECT_NE(wild.output.find("(0, 10]"), std::string::npos) << wild.output;
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "wild"));
}

}  // namespace
}  // namespace fretbuzz
