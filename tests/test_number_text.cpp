// Numbers in the output files are written in the shortest decimal form that reads back to the
// same double (std::to_chars): CSV cells, and every number in summary.json and results.h5's
// summary (nlohmann's dump() writes a longer form for about one double in 2000).
#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>
#include <string>

#include "../src/output/JsonText.hpp"
#include "fretbuzz/output/CsvWriters.hpp"
#include "fretbuzz/output/SummaryWriter.hpp"

namespace fretbuzz {
namespace {

// Doubles of every magnitude: random bit patterns and random decimals.
std::vector<double> many_doubles() {
    std::mt19937_64 g(7);
    std::uniform_real_distribution<double> exponent(-12.0, 12.0);
    std::vector<double> values{0.0005, 1e-3, 0.1, 1.0 / 3.0, 48000.0, 1.5000000000000002e-05, 23.479179565158798,
                               -6.1998388017136066e-06, 5e-324, std::numeric_limits<double>::max()};
    while (values.size() < 200000) {
        const std::uint64_t bits = g();
        double v;
        std::memcpy(&v, &bits, sizeof v);
        if (std::isfinite(v)) values.push_back(v);
        values.push_back(std::pow(10.0, exponent(g)) * ((g() & 1) != 0 ? 1.0 : -1.0));
    }
    return values;
}

std::string shortest(double v) {
    char buffer[64];
    return {buffer, std::to_chars(buffer, buffer + sizeof buffer, v).ptr};
}

TEST(NumberText, CsvCellsAreShortestAndReadBack) {
    for (const double v : many_doubles()) {
        std::string cell;
        append_number(cell, v);
        ASSERT_EQ(std::strtod(cell.c_str(), nullptr), v) << cell;
        ASSERT_EQ(cell, shortest(v));
    }
    std::string cell;
    append_number(cell, 0.0005);
    EXPECT_EQ(cell, "5e-04");  // not 0.00050000000000000001
}

TEST(NumberText, JsonNumbersAreShortestAndReadBack) {
    long longer_than_needed_by_dump = 0;
    for (const double v : many_doubles()) {
        const std::string text = json_text(nlohmann::ordered_json(v));
        ASSERT_EQ(nlohmann::ordered_json::parse(text).get<double>(), v) << text;
        // Whole numbers keep a ".0", as dump() writes them: they stay floating-point to a reader.
        std::string expected = shortest(v);
        if (expected.find_first_of(".e") == std::string::npos) expected += ".0";
        ASSERT_EQ(text, expected);
        if (nlohmann::ordered_json(v).dump().size() > text.size()) ++longer_than_needed_by_dump;
    }
    EXPECT_GT(longer_than_needed_by_dump, 0);  // what this is for
    EXPECT_EQ(json_text(nlohmann::ordered_json(std::nan(""))), "null");
}

TEST(NumberText, JsonTextIsLaidOutAsDumpLaysItOut) {
    const auto doc = nlohmann::ordered_json::parse(
        R"({"a": "x\"y", "b": [1, 2.5, {"c": null, "d": []}], "e": {}, "f": true, "g": 48000.0, "h": -3})");
    EXPECT_EQ(json_text(doc, 2), doc.dump(2));
    EXPECT_EQ(json_text(doc), doc.dump());
}

TEST(NumberText, SummaryJsonWritesTheShortestForm) {
    RunSummary s;
    s.wall_seconds = 23.479179565158798;
    s.sample_rate_hz = 48000.0;
    const std::string text = summary_json(s, {0.0005});
    EXPECT_NE(text.find("\"wall_seconds\": 23.4791795651588,"), std::string::npos) << text;
    EXPECT_NE(text.find("\"fs\": 48000.0,"), std::string::npos) << text;
    EXPECT_NE(text.find("5e-04"), std::string::npos) << text;
    EXPECT_EQ(nlohmann::ordered_json::parse(text)["wall_seconds"].get<double>(), 23.479179565158798);
}

}  // namespace
}  // namespace fretbuzz
