// `fretbuzz plot` and `fretbuzz report` end to end: a short run with snapshots, then the
// report page opened in headless Chromium (skipped where Chromium is not installed).
// Bad directories are refused with exit status 2 and a message naming DIR.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;

struct Outcome {
    int status;
    std::string output;
};

Outcome shell(const std::string& command) {
    Outcome o{-1, {}};
    FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
    if (pipe == nullptr) return o;
    char buffer[4096];
    while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) o.output += buffer;
    const int status = ::pclose(pipe);
    o.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return o;
}

std::string cli() { return FRETBUZZ_CLI; }

std::string read_file(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

std::string find_chromium() {
    for (const char* name : {"chromium", "chromium-browser", "google-chrome"}) {
        const Outcome found = shell(std::string("command -v ") + name);
        if (found.status == 0 && !found.output.empty()) return found.output.substr(0, found.output.find('\n'));
    }
    return {};
}

std::size_t count(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

class ReportCommand : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        dir_ = fs::temp_directory_path() / ("fretbuzz-report-cli-" + std::to_string(::getpid()));
        fs::remove_all(dir_);
        run_ = shell(cli() + " run bass-pop --fs 400000 --duration 0.01 --snapshots 2000 --observe 0.5 --velocity-audio -q --out " +
                     dir_.string());
        if (run_.status == 0) report_ = shell(cli() + " report -q " + dir_.string());
    }
    static void TearDownTestSuite() { fs::remove_all(dir_); }

    static fs::path dir_;
    static Outcome run_, report_;
};

fs::path ReportCommand::dir_;
Outcome ReportCommand::run_, ReportCommand::report_;

// One test for the files, one for the browser: each ctest process repeats the run and report.
TEST_F(ReportCommand, WritesEveryFigureAndASelfContainedPage) {
    ASSERT_EQ(run_.status, 0) << run_.output;
    for (const char* name : {"results.h5", "summary.json", "audio.wav", "audio_0.5m.wav", "velocity.wav", "velocity_0.5m.wav"})
        EXPECT_TRUE(fs::is_regular_file(dir_ / name)) << name;
    ASSERT_EQ(report_.status, 0) << report_.output;
    for (const char* name : {"signal.png", "signal_all_points.png", "spectrogram.png", "energy.png", "contactogram.png",
                             "snapshots.png", "animation.gif"}) {
        ASSERT_TRUE(fs::is_regular_file(dir_ / name)) << name;
        EXPECT_GT(fs::file_size(dir_ / name), 10000u) << name;
    }
    const std::string page = read_file(dir_ / "report.html");
    EXPECT_EQ(count(page, "<audio controls"), 4u);
    EXPECT_EQ(count(page, "src=\"data:image/png;base64,"), 6u);
    EXPECT_EQ(count(page, "src=\"data:image/gif;base64,"), 1u);
    EXPECT_EQ(page.find("src=\"file:"), std::string::npos);
    EXPECT_EQ(page.find("src=\"http"), std::string::npos);
    EXPECT_NE(page.find("[string]"), std::string::npos);  // the case file text
}

TEST_F(ReportCommand, RendersInHeadlessChromium) {
    ASSERT_EQ(report_.status, 0) << report_.output;
    const std::string chromium = find_chromium();
    if (chromium.empty()) GTEST_SKIP() << "chromium is not installed";
    const fs::path profile = dir_ / "chromium-profile";
    const std::string flags = " --headless --no-sandbox --disable-gpu --disable-quic --no-first-run"
                              " --disable-background-networking --disable-component-update --disable-sync"
                              " --user-data-dir=" + profile.string() + " ";
    const std::string url = "file://" + fs::absolute(dir_ / "report.html").string();
    const Outcome dom = shell("timeout 120 " + chromium + flags + "--dump-dom " + url + " 2>/dev/null");
    ASSERT_EQ(dom.status, 0) << dom.output;
    // The parsed document, not just the file: the elements the browser built.
    EXPECT_NE(dom.output.find("id=\"summary-table\""), std::string::npos);
    EXPECT_NE(dom.output.find("id=\"fig-signal\""), std::string::npos);
    EXPECT_NE(dom.output.find("id=\"fig-spectrogram\""), std::string::npos);
    EXPECT_NE(dom.output.find("id=\"fig-contactogram\""), std::string::npos);
    EXPECT_NE(dom.output.find("id=\"fig-animation\""), std::string::npos);
    EXPECT_EQ(count(dom.output, "<audio "), 4u);

    const fs::path shot = dir_ / "screenshot.png";
    const Outcome screenshot =
        shell("timeout 120 " + chromium + flags + "--window-size=1200,2400 --screenshot=" + shot.string() + " " + url);
    ASSERT_EQ(screenshot.status, 0) << screenshot.output;
    ASSERT_TRUE(fs::is_regular_file(shot)) << screenshot.output;
    const std::string png = read_file(shot);
    EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
    // A blank page compresses to a few kilobytes; plots and text make a far larger image.
    EXPECT_GT(png.size(), 60000u);
}

TEST(PlotCommand, MissingDirectoryIsAnInputError) {
    const Outcome o = shell(cli() + " plot /nonexistent/fretbuzz-dir");
    EXPECT_EQ(o.status, 2) << o.output;
    EXPECT_NE(o.output.find("DIR /nonexistent/fretbuzz-dir"), std::string::npos) << o.output;
}

TEST(PlotCommand, DirectoryWithoutResultsIsAnInputError) {
    const fs::path empty = fs::temp_directory_path() / ("fretbuzz-empty-" + std::to_string(::getpid()));
    fs::create_directories(empty);
    for (const char* command : {" plot ", " report "}) {
        const Outcome o = shell(cli() + command + empty.string());
        EXPECT_EQ(o.status, 2) << o.output;
        EXPECT_NE(o.output.find("results.h5"), std::string::npos) << o.output;
    }
    fs::remove_all(empty);
}

}  // namespace
