// The pieces of report.html: base64 for data: URIs (RFC 4648 test vectors), HTML escaping,
// and a page built from a hand-made output directory.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/io/Base64.hpp"
#include "fretbuzz/io/HtmlReport.hpp"

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
    EXPECT_NE(page.find("<tr><th>fs</th><td>400000.0</td></tr>"), std::string::npos);
    EXPECT_EQ(page.find("fig-spectrogram"), std::string::npos);  // absent figures are left out
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
