// `fretbuzz setup` end to end: a small map writes its files (CSV numbers in their shortest
// exact form, a WAV per note that fades out instead of clicking, map.json, the HTML page);
// bad options and bad instrument files are refused with a message naming the option or key
// and its range, exit status 2, and nothing written.
#include <gtest/gtest.h>

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <fstream>
#include <regex>
#include <sstream>

#include "TestSupport.hpp"
#include "fretbuzz/analysis/Recording.hpp"

namespace fretbuzz {
namespace {

using testing::run_cli;
using testing::ScratchDir;

// A quick map: two notes of the G string, coarse and short.
const std::string kQuick = " --strings G --frets 19,20 --ensemble 2 --fs 500kHz --duration 0.08 --quiet";

// The program sent SIGINT after 2 s (as Ctrl-C does), its own exit status kept.
testing::CommandResult run_cli_with_timeout(const std::string& arguments) {
    return testing::run_shell("timeout --preserve-status --signal=INT 2 " + std::string(FRETBUZZ_CLI) + " " + arguments);
}

std::string read_file(const std::filesystem::path& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

TEST(SetupCommand, AMapWritesItsFiles) {
    ScratchDir dir("setup-map");
    const std::string out = (dir.path() / "map").string();
    const auto r = run_cli("setup jazz-bass --out " + out + kQuick + " --strength soft,hard");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const std::string csv = read_file(dir.path() / "map" / "buzz_map.csv");
    EXPECT_EQ(csv.substr(0, csv.find('\n')),
              "string,fret,strength,verdict,buzz_fraction,buzz_fraction_low,buzz_fraction_high,buzz_dB,buzz_fret,"
              "touch_fraction,plucks,clean_up_to,clean_up_to_value,unit,stiffness_sensitive,status,clearance_mm,audio,"
              "pluck_dB,first_touch_s,pluck_touch_s");
    // Every number in its shortest form that reads back exactly (never 0.00050000000000000001).
    std::istringstream rows(csv);
    std::string line;
    std::getline(rows, line);
    std::size_t count = 0;
    while (std::getline(rows, line)) {
        ++count;
        std::stringstream cells(line);
        std::string cell;
        while (std::getline(cells, cell, ',')) {
            double v = 0.0;
            const auto [end, error] = std::from_chars(cell.data(), cell.data() + cell.size(), v);
            if (error != std::errc() || end != cell.data() + cell.size()) continue;  // not a number
            char shortest[32];
            const auto [last, e2] = std::to_chars(shortest, shortest + sizeof shortest, v);
            EXPECT_EQ(cell, std::string(shortest, last)) << line;
        }
    }
    EXPECT_EQ(count, 4u);  // 2 notes x 2 attacks
    for (const char* name : {"map.json", "note-G-19-soft.wav", "note-G-20-hard.wav"})
        EXPECT_TRUE(std::filesystem::is_regular_file(dir.path() / "map" / name)) << name;
    if (r.output.find("buzz_map.html was not drawn") == std::string::npos) {
        EXPECT_TRUE(std::filesystem::is_regular_file(dir.path() / "map" / "buzz_map.html"));
    }
    // The notes fade out over their last 50 ms: no click where the run stops.
    const Recording wav = read_recording(dir.path() / "map" / "note-G-19-hard.wav");
    double peak = 0.0, tail = 0.0;
    for (double s : wav.samples) peak = std::max(peak, std::abs(s));
    for (std::size_t i = wav.samples.size() - 20; i < wav.samples.size(); ++i) tail = std::max(tail, std::abs(wav.samples[i]));
    EXPECT_GT(peak, 0.5);
    EXPECT_LT(tail, 1e-3 * peak);
}

// A what-if in an inch file: a bare number is inches, each value is said back as it was read,
// and the map is of the neck so changed (relief 0.012 in = 0.3048 mm under the first string).
TEST(SetupCommand, AWhatIfReadsTheFilesUnitsAndSaysWhatItRead) {
    ScratchDir dir("setup-units");
    std::string text = read_file(std::filesystem::path(FRETBUZZ_SOURCE_DIR) / "cases/instruments/jazz-bass.toml");
    for (const auto& [from, to] : {std::pair<std::string, std::string>{"nut = \"0.75 mm\"", "nut = \"0.030 in\""},
                                   {"action12 = \"2.7 mm\"", "action12 = \"7/64 in\""}})
        text.replace(text.find(from), from.size(), to);
    const auto file = dir.path() / "inch-bass.toml";
    std::ofstream(file) << text;
    const std::string out = (dir.path() / "map").string();
    const auto r = run_cli("setup " + file.string() + " --out " + out + kQuick +
                           " --relief 0.012 --action 17:G=3/32in --saddle-change E=-10thou");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    for (const char* said : {"fretbuzz: relief: 0.012 in (0.305 mm)", "fretbuzz: action at fret 17, G: 3/32 in (2.381 mm)",
                             "fretbuzz: saddle change, E: -10 thou (-0.254 mm)"})
        EXPECT_NE(r.output.find(said), std::string::npos) << said << "\n" << r.output;
    std::smatch m;
    const std::string json = read_file(dir.path() / "map" / "map.json");
    ASSERT_TRUE(std::regex_search(json, m, std::regex("\"relief_gap_m\": ?([-0-9.eE+]+)"))) << json.substr(0, 2000);
    EXPECT_NEAR(std::stod(m[1].str()), 0.012 * 0.0254, 1e-12);
    EXPECT_NE(json.find("--action 17:G=3/32in"), std::string::npos);
}

// --advice writes its searches as JSON and text; --compare marks the notes that changed.
TEST(SetupCommand, AdviceAndComparisonAreWritten) {
    ScratchDir dir("setup-advice");
    const std::string first = (dir.path() / "a").string(), second = (dir.path() / "b").string();
    const std::string quick = " --strings G --ensemble 1 --fs 300kHz --duration 0.05 --quiet --strength medium";
    ASSERT_EQ(run_cli("setup jazz-bass --out " + first + quick).exit_code, 0);
    const auto r = run_cli("setup jazz-bass --out " + second + quick + " --fret-offset 15=0.08 --compare " + first +
                           " --advice");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const std::string advice = read_file(dir.path() / "b" / "advice.txt");
    EXPECT_NE(advice.find("string G: action at fret 12 now"), std::string::npos) << advice;
    // No --tolerate: as set-ups do, said on the first line.
    EXPECT_NE(advice.find("frets 0-15, tolerating marginal notes, notes above fret 15 (as set-ups do"), std::string::npos)
        << advice;
    EXPECT_NE(advice.find("stands proud"), std::string::npos) << advice;  // which ones: SetupAdvice's tests
    EXPECT_NE(advice.find("relief (gap at fret 8) now"), std::string::npos) << advice;
    EXPECT_NE(read_file(dir.path() / "b" / "advice.json").find("\"lowest_clean_action12_mm\""), std::string::npos);
    const std::string compare = read_file(dir.path() / "b" / "compare.csv");
    EXPECT_EQ(std::count(compare.begin(), compare.end(), '\n'), 22) << compare;  // a header and 21 notes
    EXPECT_NE(compare.find("G,14,medium,"), std::string::npos) << compare;
}

// --dress writes what comes off each fret (mm and thousandths of an inch) and the map after it.
TEST(SetupCommand, TheFretDressIsWritten) {
    ScratchDir dir("setup-dress");
    const std::string out = (dir.path() / "d").string();
    const auto r = run_cli("setup jazz-bass --out " + out + kQuick + " --strength medium --dress --fall-away 17");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    std::istringstream csv(read_file(dir.path() / "d" / "dress.csv"));
    std::string line;
    std::getline(csv, line);
    EXPECT_EQ(line, "fret,remove_mm,remove_thou");
    std::size_t rows = 0;
    while (std::getline(csv, line)) {
        ++rows;
        double mm = 0.0, thou = 0.0;
        ASSERT_EQ(std::sscanf(line.c_str(), "%*d,%lf,%lf", &mm, &thou), 2) << line;
        EXPECT_NEAR(thou, mm / 25.4 * 1e3, 1e-3) << line;  // the same depth in thousandths of an inch
        EXPECT_GE(mm, 0.0);
        EXPECT_LE(mm, 0.3 + 1e-9);  // the default depth
    }
    EXPECT_EQ(rows, 20u);  // every fret
    const std::string after = read_file(dir.path() / "d" / "dress_map.csv");
    EXPECT_NE(after.find("G,19,medium,"), std::string::npos) << after;
    EXPECT_NE(read_file(dir.path() / "d" / "map.json").find("\"dress\": {"), std::string::npos);
}

// Ctrl-C: exit status 130, a message that says the map is lost, and nothing written.
TEST(SetupCommand, CtrlCStopsTheMapAndWritesNothing) {
    ScratchDir dir("setup-interrupt");
    const std::string out = (dir.path() / "map").string();
    const auto r = run_cli_with_timeout("setup jazz-bass --fs 4MHz --duration 1 --out " + out + " --quiet");
    EXPECT_EQ(r.exit_code, 130) << r.output;
    EXPECT_NE(r.output.find("the map is lost"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("nothing was written"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(out));
    for (const auto& e : std::filesystem::directory_iterator(dir.path())) ADD_FAILURE() << "left behind: " << e.path();
}

struct Refusal {
    std::string arguments;
    std::vector<std::string> says;
};

TEST(SetupCommand, BadOptionsAreRefusedAndNothingIsWritten) {
    ScratchDir dir("setup-bad");
    const std::string out = (dir.path() / "never").string();
    const std::vector<Refusal> cases = {
        {"--frets 0-20000000", {"--frets", "[0, 20]"}},
        {"--frets 0-99999999999", {"--frets", "[0, 20]"}},
        {"--frets 21", {"--frets", "21"}},
        {"--strength -1e-3", {"--strength", "(0, 10] mm"}},
        {"--strength loud", {"--strength", "soft, medium, hard, pick, pop, slap"}},
        {"--strength 11m/s", {"--strength", "(0, 10] m/s"}},
        {"--strings E,Q", {"string \"Q\"", "E, A, D, G"}},
        {"--relief 5", {"--relief", "[-2, 2] mm"}},
        {"--action12 E=0.01", {"--action12 E", "fret"}},
        {"--action12 E", {"--action12", "STRING=LENGTH"}},
        {"--action 17E=3/32in", {"--action", "FRET:STRING=LENGTH"}},
        {"--action 21:E=3/32in", {"--action 21", "[2, 20]"}},
        {"--action 17:E=3/32furlong", {"--action 17:E", "units"}},
        {"--saddle-change E=-9mm", {"--saddle-change E", "[-5, 5] mm"}},
        {"--saddle-change E=-0.25mm --saddle E=10mm", {"--saddle-change E", "--saddle E", "give one"}},
        {"--relief-change 5mm", {"--relief-change", "[-1, 1] mm"}},
        {"--relief 0.3 --relief-change 0.1mm", {"--relief", "--relief-change", "give one"}},
        {"--nut-change E=x", {"--nut-change E", "units"}},
        {"--fret-offset 25=0.1", {"--fret-offset", "[1, 20]"}},
        {"--fret-offset 5=3", {"--fret-offset 5", "[-1, 1] mm"}},
        {"--jobs 0", {"--jobs", "[1, 256]"}},
        {"--ensemble 1000", {"--ensemble", "[1, 200]"}},
        {"--fs 10", {"--fs", "[50000, 2e7]"}},
        {"--compare " + (dir.path() / "nothing").string(), {"--compare", "buzz_map.csv"}},
        {"--advice --tolerate loud", {"--tolerate loud", "marginal", "above=K", "[0, 20]"}},
        {"--advice --tolerate above=30", {"--tolerate above=30", "[0, 20]"}},
        {"--tolerate marginal", {"--tolerate", "--advice or --dress"}},
        {"--dress --dress-depth 5", {"--dress-depth", "[0.01, 1] mm"}},
        {"--dress --crown 2", {"--crown", "[0, 1.2 mm)"}},
        {"--dress --fall-away 20", {"--fall-away 20", "[1, 18]"}},
        {"--dress --fall-away 30", {"--fall-away 30", "[1, 20]"}},
        {"--fall-away 15", {"--fall-away", "--dress"}},
    };
    for (const Refusal& c : cases) {
        const auto r = run_cli("setup jazz-bass --out " + out + " " + c.arguments);
        EXPECT_EQ(r.exit_code, 2) << c.arguments << "\n" << r.output;
        for (const std::string& s : c.says) EXPECT_NE(r.output.find(s), std::string::npos) << c.arguments << "\n" << r.output;
        EXPECT_EQ(r.output.find("Traceback"), std::string::npos) << r.output;
        EXPECT_FALSE(std::filesystem::exists(out)) << c.arguments;
    }
    const auto unknown = run_cli("setup banjo --out " + out);
    EXPECT_EQ(unknown.exit_code, 2);
    EXPECT_NE(unknown.output.find("jazz-bass"), std::string::npos) << unknown.output;
}

TEST(SetupCommand, BadInstrumentFilesAreRefusedNamingTheKey) {
    ScratchDir dir("setup-file");
    std::string text = read_file(std::filesystem::path(FRETBUZZ_SOURCE_DIR) / "cases/instruments/jazz-bass.toml");
    int files = 0;
    const auto edit = [&](const std::string& from, const std::string& to) {
        std::string t = text;
        t.replace(t.find(from), from.size(), to);
        const auto path = dir.path() / ("bad" + std::to_string(++files) + ".toml");
        std::ofstream(path) << t;
        return path.string();
    };
    const std::string out = (dir.path() / "never").string();
    const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
        {edit("fret_height = \"1.2 mm\"", "fret_height = \"9 mm\""), {"neck.fret_height", "(0, 5] mm"}},
        {edit("action12 = \"2.7 mm\"", "action12 = \"2.7 furlongs\""), {"string[0].action12", "units"}},
        {edit("scale = \"863 mm\"", "scale = 863"), {"neck.scale", "unit"}},
        {edit("frets = 20", "frets = 20\nfret_offsets = { 30 = \"0.1 mm\" }"), {"neck.fret_offsets.30", "frets 1 to 20"}},
        // Attacks a hand cannot play: a finger pluck pulled away from the board, a slap at 25 m/s.
        {edit("[simulation]", "[attack]\nangle = -15\n\n[simulation]"), {"attack.angle", "[0, 90] degrees"}},
        {edit("[simulation]", "[attack]\nslap = \"25 m/s\"\n\n[simulation]"), {"attack.slap", "(0, 10] m/s"}},
    };
    for (const auto& [path, says] : cases) {
        const auto r = run_cli("setup " + path + " --out " + out);
        EXPECT_EQ(r.exit_code, 2) << r.output;
        for (const std::string& s : says) EXPECT_NE(r.output.find(s), std::string::npos) << r.output;
        EXPECT_FALSE(std::filesystem::exists(out));
    }
}

}  // namespace
}  // namespace fretbuzz
