// Strings as they are sold: every named set (cases/strings/sets.toml) loads, its tensions are
// those of the maker's chart (its unit weights give them back to 2 %, and an instrument
// strung with it at the chart's scale and pitches pulls them), its strings bend on their
// cores when the file gives none, the five-string bass is built in, and a string whose mass
// does not fit its gauge is warned about.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "SetupTestSupport.hpp"
#include "TestSupport.hpp"
#include "fretbuzz/input/BuiltinFiles.hpp"
#include "fretbuzz/input/InstrumentFile.hpp"
#include "fretbuzz/model/SteelWire.hpp"
#include "fretbuzz/model/TautString.hpp"
#include "fretbuzz/setup/Attack.hpp"
#include "fretbuzz/setup/BuzzMap.hpp"
#include "fretbuzz/setup/StringNeck.hpp"

namespace fretbuzz {
namespace {

constexpr double kInch = 0.0254;
constexpr double kPound = 4.4482216152605;  // N

// An instrument strung with the set at the chart's own scale and pitches, no core given.
std::string instrument_with(const StringSet& set) {
    std::ostringstream t;
    t.precision(17);
    t << "name = \"chart\"\n[neck]\nscale = \"" << set.scale_length_m << " m\"\nfrets = 21\nfret_height = \"1 mm\"\n"
      << "[strings]\nset = \"" << set.name << "\"\n";
    for (std::size_t k = 0; k < set.strings.size(); ++k)
        t << "[[string]]\nname = \"s" << k << "\"\npitch = \"" << set.strings[k].frequency_hz
          << " Hz\"\nnut = \"0.6 mm\"\naction12 = \"3 mm\"\n";
    t << "[attack]\nposition = \"120 mm\"\nsoft = \"0.3 mm\"\nmedium = \"0.5 mm\"\nhard = \"0.7 mm\"\n";
    return t.str();
}

// The set of these gauges (in thousandths of an inch, low to high), or a failure.
const StringSet* set_of_gauges(const std::vector<int>& thousandths) {
    for (const StringSet& set : builtin_string_sets()) {
        if (set.strings.size() != thousandths.size()) continue;
        bool same = true;
        for (std::size_t k = 0; k < thousandths.size(); ++k)
            same = same && std::abs(set.strings[k].gauge_m - thousandths[k] * 1e-3 * kInch) < 1e-9;
        if (same) return &set;
    }
    ADD_FAILURE() << "no set of gauges " << thousandths.front() << "-" << thousandths.back();
    return nullptr;
}

TEST(SteelWire, APlainStringsUnitWeightGivesItsGauge) {
    // D'Addario's plain steel .010 in (PL010) weighs 0.00002215 lb/in: a solid music wire
    // of that mass per length is 0.2533 mm thick, its gauge 0.254 mm within 0.5 %.
    const double kLbPerIn = 0.45359237 / kInch;  // kg/m
    const SteelWire wire = SteelWire::of_linear_density(0.00002215 * kLbPerIn);
    EXPECT_NEAR(wire.diameter_m, 0.010 * kInch, 0.005 * 0.010 * kInch);
    EXPECT_NEAR(wire.linear_density(), 0.00002215 * kLbPerIn, 1e-15);
}

TEST(StringSets, EverySetLoadsAndItsTensionsMatchTheChart) {
    const std::vector<StringSet> sets = builtin_string_sets();
    ASSERT_GE(sets.size(), 8u);
    std::size_t with_unit_weights = 0;
    for (const StringSet& set : sets) {
        SCOPED_TRACE(set.name);
        EXPECT_FALSE(set.source.empty());
        std::size_t checked = 0;
        for (const StringSetEntry& e : set.strings) {
            if (!e.unit_weight) continue;
            // The chart's tension from the chart's unit weight: T = UW (2 L f)^2.
            const double t = TautString::tuned_with_mass(set.scale_length_m, *e.unit_weight, e.frequency_hz).tension_n;
            EXPECT_NEAR(t, e.tension_n, 0.02 * e.tension_n) << e.gauge_m / kInch << " in";
            ++checked;
        }
        with_unit_weights += checked == set.strings.size();
        // Strung on an instrument of the chart's scale at the chart's pitches, the strings pull
        // what the chart says, and bend on the set's cores (the file names none).
        const Instrument inst = parse_instrument(instrument_with(set), "chart.toml", DataSource::builtin());
        ASSERT_EQ(inst.strings.size(), set.strings.size());
        EXPECT_TRUE(inst.warnings.empty()) << inst.warnings.front();
        for (std::size_t k = 0; k < set.strings.size(); ++k) {
            const StringSetEntry& e = set.strings[k];
            EXPECT_NEAR(inst.strings[k].tension_n, e.tension_n, 0.02 * e.tension_n) << k;
            EXPECT_EQ(inst.strings[k].gauge_m, e.gauge_m);
            const double core = e.plain ? e.gauge_m : set.core_ratio * e.gauge_m;
            EXPECT_NEAR(inst.strings[k].bending_stiffness, SteelWire{core}.bending_stiffness(),
                        1e-12 * inst.strings[k].bending_stiffness);
            EXPECT_LT(e.core_m, e.gauge_m + 1e-15);
        }
    }
    EXPECT_GE(with_unit_weights, 8u);
    // Among them the sets luthiers ask for: bass 45-105, five-string 45-130, guitar 9-42, 10-46, 11-49.
    for (const std::vector<int>& gauges :
         {std::vector<int>{105, 80, 65, 45}, {130, 100, 80, 65, 45}, {42, 32, 24, 16, 11, 9}, {46, 36, 26, 17, 13, 10},
          {49, 38, 28, 18, 14, 11}})
        set_of_gauges(gauges);
}

// 10-46 at 25.5 in, the chart's own figures: E2 17.5 lb from 0.00038216 lb/in.
TEST(StringSets, TheChartsUnitsAreThoseOfTheTensionGuide) {
    const StringSet& exl110 = builtin_string_set("daddario-exl110", "test");
    EXPECT_NEAR(exl110.scale_length_m, 25.5 * kInch, 1e-15);
    EXPECT_NEAR(*exl110.strings[0].unit_weight, 0.00038216 * 0.45359237 / kInch, 1e-12);
    EXPECT_NEAR(exl110.strings[0].tension_n, 17.5 * kPound, 1e-9);
    EXPECT_TRUE(exl110.strings[5].plain);
    EXPECT_FALSE(exl110.strings[0].plain);
    EXPECT_THROW(builtin_string_set("daddario-exl999", "strings.set"), InputError);
}

// The built-in five-string: a 35 in neck strung with EXL170-5, whose tensions at 35 in are the
// chart's (at 34 in) times (35 / 34)^2; its low B is played like any other string.
TEST(StringSets, TheFiveStringBassIsBuiltInFromItsSet) {
    const Instrument bass = load_instrument("bass-5");
    ASSERT_EQ(bass.strings.size(), 5u);
    const StringSet& set = builtin_string_set("daddario-exl170-5", "test");
    for (std::size_t k = 0; k < 5; ++k) {
        EXPECT_NEAR(bass.strings[k].scale_length_m, 35.0 * kInch, 1e-15);
        EXPECT_NEAR(bass.strings[k].tension_n, set.strings[k].tension_n * std::pow(35.0 / 34.0, 2),
                    1e-12 * bass.strings[k].tension_n);
        EXPECT_NEAR(bass.strings[k].bending_stiffness, SteelWire{set.strings[k].core_m}.bending_stiffness(), 1e-18);
    }
    EXPECT_NEAR(bass.strings[0].frequency_hz, 30.8677, 1e-4);  // B0
    EXPECT_TRUE(bass.warnings.empty());
    for (std::size_t s = 0; s < 5; ++s) {
        const StringNeck neck(bass, s);
        EXPECT_NEAR(neck.gap(17), (s < 3 ? 7.0 : 6.0) / 64.0 * kInch, 1e-15) << s;
        for (std::size_t k = 0; k <= neck.fret_count(); ++k) EXPECT_FALSE(neck.rests_on(k).has_value()) << s << " " << k;
    }
    MapRequest request;
    request.strings = {0};
    request.frets = {0, 5};
    request.attacks = parse_attacks("soft", bass.attack);
    EXPECT_EQ(map_notes(bass, request).size(), 2u);
}

// A unit weight entered 10 times too small (a slip of the unit) reads, and is warned about,
// naming the string; the warning shows in the program's output.
TEST(StringSets, AStringTooLightForItsGaugeIsWarnedAbout) {
    const std::string base(*find_builtin_file("instruments/jazz-bass.toml"));
    EXPECT_TRUE(load_instrument("jazz-bass").warnings.empty());
    const std::string light = testing::replaced(base, "mu = \"0.00669 kg/m\"", "mu = \"0.000669 kg/m\"");
    const Instrument bass = parse_instrument(light, "light.toml", DataSource::builtin());
    ASSERT_EQ(bass.warnings.size(), 1u);
    EXPECT_NE(bass.warnings[0].find("string[3].mu"), std::string::npos) << bass.warnings[0];
    EXPECT_NE(bass.warnings[0].find("0.0835 times a steel rod"), std::string::npos) << bass.warnings[0];
    // The same string from a tension 10 times too small for its gauge (mu from pitch and T).
    const std::string slack = testing::replaced(testing::replaced(light, "mu = \"0.000669 kg/m\"\n", ""),
                                                "tension = \"191.6 N\"", "tension = \"19.16 N\"\npitch = \"G2\"");
    EXPECT_EQ(parse_instrument(slack, "slack.toml", DataSource::builtin()).warnings.size(), 1u);
    testing::ScratchDir dir("light-string");
    const auto path = dir.path() / "light.toml";
    std::ofstream(path) << light;
    const auto r = testing::run_cli("setup " + path.string() + " --strings G --frets 0 --strength soft --ensemble 1 "
                                    "--duration 0.02 --quiet --out " + (dir.path() / "map").string());
    EXPECT_NE(r.output.find("fretbuzz: warning: string[3].mu"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace fretbuzz
