// `fretbuzz convergence` end to end: the table, the CSV, the plot, and clear refusals.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

struct CommandResult {
    int status = -1;
    std::string output;  // stdout and stderr together
};

CommandResult run_cli(const std::string& arguments) {
    const std::string command = std::string(FRETBUZZ_CLI) + " " + arguments + " 2>&1";
    CommandResult result;
    FILE* pipe = ::popen(command.c_str(), "r");
    if (!pipe) return result;
    std::array<char, 4096> buffer{};
    while (std::fgets(buffer.data(), static_cast<int>(buffer.size()), pipe)) result.output += buffer.data();
    const int status = ::pclose(pipe);
    result.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return result;
}

std::filesystem::path fresh_directory(const std::string& name) {
    const auto dir = std::filesystem::temp_directory_path() / ("fretbuzz-test-" + name);
    std::filesystem::remove_all(dir);
    return dir;
}

std::vector<std::string> read_lines(const std::filesystem::path& path) {
    std::ifstream in(path);
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
}

TEST(ConvergenceCommand, WritesTableCsvAndPlot) {
    const auto dir = fresh_directory("convergence");
    const CommandResult r =
        run_cli("convergence bass-pop --fs 100000,200000 --reference-fs 400000 --window 0.006 --out " + dir.string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("rel. L2 error"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("(reference)"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("100000"), std::string::npos) << r.output;
    const std::vector<std::string> csv = read_lines(dir / "convergence.csv");
    ASSERT_EQ(csv.size(), 3u);
    EXPECT_EQ(csv[0], "parameter,value,relative_error,observed_order,meets_threshold,wall_seconds");
    EXPECT_EQ(csv[1].rfind("fs,100000,", 0), 0u) << csv[1];
    EXPECT_EQ(csv[2].rfind("fs,200000,", 0), 0u) << csv[2];
    // The coarsest level has no order; the next one has.
    std::stringstream second(csv[2]);
    std::vector<std::string> fields;
    for (std::string f; std::getline(second, f, ',');) fields.push_back(f);
    ASSERT_EQ(fields.size(), 6u);
    EXPECT_GT(std::stod(fields[3]), 0.0);
    if (std::filesystem::exists("/usr/bin/python3") && r.output.find("no plot") == std::string::npos) {
        EXPECT_GT(std::filesystem::file_size(dir / "convergence.png"), 1000u);
    }
    std::filesystem::remove_all(dir);
}

TEST(ConvergenceCommand, RefusesBadInputWithAClearMessage) {
    const auto dir = fresh_directory("convergence-bad").string();
    struct Case {
        std::string arguments, expected;
    };
    const std::vector<Case> cases = {
        {"--window 0.01", "list of levels is empty"},
        {"--fs 100000,0 --window 0.01", "--fs = 0"},
        {"--fs 100000,-200000 --window 0.01", "--fs = -200000"},
        {"--fs 100000,200000 --window 0.2 --duration 0.1", "--window"},
        {"--fs 100001,200000 --window 0.01", "no common comparison rate"},
        {"--fs 100000,800000 --reference-fs 400000 --window 0.01", "--reference-fs"},
    };
    for (const Case& c : cases) {
        const CommandResult r = run_cli("convergence bass-pop " + c.arguments + " --out " + dir);
        EXPECT_EQ(r.status, 2) << c.arguments << "\n" << r.output;
        EXPECT_NE(r.output.find(c.expected), std::string::npos) << c.arguments << "\n" << r.output;
        EXPECT_FALSE(std::filesystem::exists(dir)) << "a refused study must leave no output";
    }
}

}  // namespace
