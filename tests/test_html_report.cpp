// The pieces of report.html: base64 for data: URIs (RFC 4648 test vectors), HTML escaping,
// and a page built from a hand-made output directory.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/output/Base64.hpp"
#include "fretbuzz/output/HtmlReport.hpp"
#include "fretbuzz/output/SummaryWriter.hpp"

namespace fretbuzz {
namespace {

namespace fs = std::filesystem;

TEST(Base64, MatchesTheRfc4648TestVectors) {
    EXPECT_EQ(base64_encode(""), "");
    EXPECT_EQ(base64_encode("f"), "Zg==");
    EXPECT_EQ(base64_encode("fo"), "Zm8=");
    EXPECT_EQ(base64_encode("foo"), "Zm9v");
    EXPECT_EQ(base64_encode("foob"), "Zm9vYg==");
    EXPECT_EQ(base64_encode("fooba"), "Zm9vYmE=");
    EXPECT_EQ(base64_encode("foobar"), "Zm9vYmFy");
    EXPECT_EQ(base64_encode(std::string("\xff\xfe\x00", 3)), "//4A");
}

TEST(HtmlReport, EscapesMarkup) {
    EXPECT_EQ(html_escape("a<b & \"c\" 'd'>"), "a&lt;b &amp; &quot;c&quot; &#39;d&#39;&gt;");
}

class ReportDirectory : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("fretbuzz-report-test-" + std::to_string(::getpid()));
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    void write(const std::string& name, const std::string& bytes) { std::ofstream(dir_ / name, std::ios::binary) << bytes; }
    fs::path dir_;
};

TEST_F(ReportDirectory, EmbedsFiguresAndAudioAndTabulatesTheSummary) {
    write("summary.json", R"({"case": "demo <1>", "fs": 400000.0, "observation_points_m": [0.854, 0.5]})");
    write("signal.png", "PNG!");
    write("audio.wav", "RIFF");
    write("audio_0.5m.wav", "RIFF2");
    const std::string page = render_html_report(dir_);
    EXPECT_NE(page.find("<title>fretbuzz: demo &lt;1&gt;</title>"), std::string::npos);
    EXPECT_NE(page.find("src=\"data:image/png;base64," + base64_encode("PNG!") + "\""), std::string::npos);
    EXPECT_NE(page.find("src=\"data:audio/wav;base64," + base64_encode("RIFF") + "\""), std::string::npos);
    EXPECT_NE(page.find("src=\"data:audio/wav;base64," + base64_encode("RIFF2") + "\""), std::string::npos);
    EXPECT_NE(page.find("x = 0.5 m"), std::string::npos);
    EXPECT_NE(page.find("<tr><th>Sampling rate fs</th><td>400000 Hz</td></tr>"), std::string::npos) << page;
    EXPECT_EQ(page.find("fig-spectrogram"), std::string::npos);  // absent figures are left out
}

TEST_F(ReportDirectory, ShowsUnitsRoundedNumbersGainsAndProvenance) {
    write("summary.json", R"({"case": "demo", "duration": 0.0123456789, "energy_initial_J": 1.234567890123e-05,
        "contact_steps": 42, "some_new_key": 3.14159265358979,
        "audio": [{"file": "audio.wav", "x_m": 0.854, "signal": "displacement", "full_scale": 0.001234567,
                   "full_scale_unit": "m", "rate_hz": 48000.0, "fade_in_s": 0.005, "fade_out_s": 0.0}],
        "provenance": {"fretbuzz_version": "9.9.9", "created_utc": "2026-01-01T00:00:00Z", "command_line": "fretbuzz run x",
                       "platform": "Linux", "case_sha256": "abc123", "case_text": "name = 1",
                       "mode_table": {"frequency_hz": [98.0, 196.0, 294.5], "sigma_per_s": [1, 2, 3]}}})");
    const std::string page = render_html_report(dir_);
    EXPECT_NE(page.find("<tr><th>Simulated duration</th><td>0.01235 s</td></tr>"), std::string::npos) << page;
    EXPECT_NE(page.find("<tr><th>Initial energy H(1/2)</th><td>1.235e-05 J</td></tr>"), std::string::npos);
    EXPECT_NE(page.find("<tr><th>Steps with contact (obstacle)</th><td>42</td></tr>"), std::string::npos);
    EXPECT_NE(page.find("<tr><th>some_new_key</th><td>3.142</td></tr>"), std::string::npos);
    EXPECT_NE(page.find("<td>0.001235 m</td>"), std::string::npos);  // the WAV's full scale
    EXPECT_NE(page.find("<tr><th>fretbuzz version</th><td>9.9.9</td></tr>"), std::string::npos);
    EXPECT_NE(page.find("<tr><th>Case file SHA-256</th><td>abc123</td></tr>"), std::string::npos);
    EXPECT_NE(page.find("3 modes, 98 to 294.5 Hz"), std::string::npos);
    EXPECT_EQ(page.find("name = 1"), std::string::npos);  // the case text is shown from results.h5 only
}

// Every key summary.json holds for a played run with two polarisations is named in words with
// its unit, and each energy row says what it counts.
TEST_F(ReportDirectory, NamesEverySummaryKeyAndWhatEachEnergyRowCounts) {
    RunSummary s;
    s.case_name = "played";
    s.fingers = 1;
    s.gestures = 1;
    s.polarisations = 2;
    s.energy_initial_j = 0.0;
    s.energy_final_j = 1.0e-3;
    s.dissipated_j = 7.0e-4;  // damping 3e-4 (z 2e-4, y 1e-4), fingers 1e-4, friction 3e-4
    s.damping_y_j = 1.0e-4;
    s.finger_loss_j = 1.0e-4;
    s.friction_j = 3.0e-4;
    s.work_j = 1.7e-3;
    s.finger_energy_final_j = 2.0e-5;
    s.energy_y_final_j = 4.0e-4;
    write("summary.json", summary_json(s, {0.854}));
    const std::string page = render_html_report(dir_);
    const auto json = nlohmann::ordered_json::parse(summary_json(s, {0.854}));
    for (const auto& [key, value] : json.items())
        EXPECT_EQ(page.find("<th>" + key + "</th>"), std::string::npos) << key << " is shown under its own name";
    EXPECT_NE(page.find("<tr><th>Energy dissipated, all losses</th><td>0.0007 J</td></tr>"), std::string::npos) << page;
    EXPECT_NE(page.find("<tr><th>Energy dissipated by damping</th><td>0.0003 J</td></tr>"), std::string::npos) << page;
    EXPECT_NE(page.find("<tr><th>Energy dissipated by friction</th><td>0.0003 J</td></tr>"), std::string::npos);
    EXPECT_NE(page.find("<tr><th>Work done on the string by fingers, forces and pluckers</th><td>0.0017 J</td></tr>"),
              std::string::npos);
    EXPECT_NE(page.find("Energy dissipated in the contacts of fingers and pluckers</th><td>0.0001 J"), std::string::npos);
    EXPECT_NE(page.find("relative to max(H(1/2), work)"), std::string::npos);
}

TEST_F(ReportDirectory, WithoutSummaryNamesTheDirectory) {
    try {
        render_html_report(dir_);
        FAIL() << "expected an InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("DIR " + dir_.string()), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("summary.json"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace fretbuzz
