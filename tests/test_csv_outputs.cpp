// The CSV outputs are formatted and written on threads of their own while the run goes
// on: their bytes must be those of formatting every row in order on the run's thread, and
// a write that fails on the thread must still stop the run with the file's name.
#include <gtest/gtest.h>

#include <sys/resource.h>

#include <csignal>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "TestSupport.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/CsvTable.hpp"
#include "fretbuzz/output/CsvWriters.hpp"
#include "fretbuzz/run/Simulation.hpp"

namespace fretbuzz {
namespace {

namespace fs = std::filesystem;

// The sitar at 48 kHz with its modes below fs/2: a row every step, with a bridge force.
Case sitar_at_48k(double duration_s) { return testing::builtin_at_rate("sitar", 48000.0, duration_s); }

// What each CSV gets, formatted on the spot, row after row: the straightforward path.
class RowsInOrder : public RunObserver {
public:
    void observation(double t, std::span<const double> u) override {
        line(observation_, t, u);
    }
    void bridge_force(double t, double force) override {
        const double f[] = {force};
        line(bridge_, t, f);
    }
    void energy(double t, double h, double contact, double dissipated) override {
        const double terms[] = {h, contact, dissipated};
        line(energy_, t, terms);
    }
    std::string observation_, bridge_, energy_;

private:
    static void line(std::string& text, double t, std::span<const double> values) {
        append_number(text, t);
        for (double v : values) {
            text += ',';
            append_number(text, v);
        }
        text += '\n';
    }
};

std::string read_text(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

std::string body(const std::string& text) { return text.substr(text.find('\n') + 1); }

TEST(CsvOutputs, ThreadedFilesHoldEveryRowAsFormattedInOrder) {
    // 0.5 s at 48 kHz: 24 000 rows, several of the writers' blocks per file.
    const Case c = sitar_at_48k(0.5);
    testing::ScratchDir scratch("csv-outputs");
    ObservationCsvWriter observation(scratch.path() / "observation.csv");
    EnergyCsvWriter energy(scratch.path() / "energy.csv");
    BridgeForceCsvWriter bridge(scratch.path() / "bridge_force.csv");
    RowsInOrder expected;
    RunObserver* observers[] = {&observation, &energy, &bridge, &expected};
    const RunSummary summary = simulate(c, observers);

    const std::string observation_text = read_text(scratch.path() / "observation.csv");
    const std::string energy_text = read_text(scratch.path() / "energy.csv");
    const std::string bridge_text = read_text(scratch.path() / "bridge_force.csv");
    EXPECT_EQ(body(observation_text), expected.observation_);
    EXPECT_EQ(body(energy_text), expected.energy_);
    EXPECT_EQ(body(bridge_text), expected.bridge_);
    EXPECT_EQ(energy_text.substr(0, energy_text.find('\n')), "t_s,energy_J,contact_energy_J,dissipated_J");
    EXPECT_EQ(bridge_text.substr(0, bridge_text.find('\n')), "t_s,bridge_force_N");

    // Read back, the energy balance of the lossy scheme holds row by row to round-off:
    // energy + dissipated stays what it was at the first row (nothing is lost in the text).
    const CsvTable table = parse_csv(energy_text, "energy.csv", 4);
    ASSERT_EQ(table.rows.size(), static_cast<std::size_t>(summary.steps));
    const double total = table.rows.front()[1] + table.rows.front()[3];
    double worst = 0.0;
    for (const auto& row : table.rows) worst = std::max(worst, std::abs(row[1] + row[3] - total));
    EXPECT_LT(worst, 1e-10 * total);  // round-off over 24 000 steps
    EXPECT_EQ(table.rows.back()[1], summary.energy_final_j);
}

// Writes past this size fail with EFBIG (the signal that would kill the process ignored).
class FileSizeLimit {
public:
    explicit FileSizeLimit(rlim_t bytes) {
        old_handler_ = std::signal(SIGXFSZ, SIG_IGN);
        getrlimit(RLIMIT_FSIZE, &old_);
        rlimit limit = old_;
        limit.rlim_cur = bytes;
        setrlimit(RLIMIT_FSIZE, &limit);
    }
    ~FileSizeLimit() {
        setrlimit(RLIMIT_FSIZE, &old_);
        std::signal(SIGXFSZ, old_handler_);
    }
    FileSizeLimit(const FileSizeLimit&) = delete;
    FileSizeLimit& operator=(const FileSizeLimit&) = delete;

private:
    rlimit old_{};
    void (*old_handler_)(int) = nullptr;
};

TEST(CsvOutputs, AWriteFailingOnTheWritersThreadStopsTheRunNamingTheFile) {
    const Case c = sitar_at_48k(0.5);
    testing::ScratchDir scratch("csv-failure");
    const fs::path path = scratch.path() / "energy.csv";
    std::string message;
    {
        EnergyCsvWriter energy(path);
        RunObserver* observers[] = {&energy};
        const FileSizeLimit limit(64 << 10);  // the header fits, the rows do not
        try {
            simulate(c, observers);
        } catch (const std::runtime_error& e) {
            message = e.what();
        }
    }
    EXPECT_NE(message.find(path.string()), std::string::npos) << message;
    EXPECT_NE(message.find("File too large"), std::string::npos) << message;
}

}  // namespace
}  // namespace fretbuzz
