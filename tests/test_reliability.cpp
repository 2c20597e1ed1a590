// Complete results or nothing: a run that fails (a full disk), is interrupted (SIGINT,
// SIGTERM, SIGKILL) or races another run into the same folder leaves either the earlier
// results untouched or one run's complete set; every error exits 2, 1 or 3 and names its
// cause; files a case names are read as someone else's input (bounded, regular files).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "TestSupport.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/StringsCaseFile.hpp"
#include "fretbuzz/output/AudioWriter.hpp"
#include "fretbuzz/output/CsvWriters.hpp"
#include "fretbuzz/output/OutputDirectory.hpp"
#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/run/StringsRun.hpp"

extern char** environ;

namespace fretbuzz {
namespace {

namespace fs = std::filesystem;
using testing::run_cli;
using testing::ScratchDir;

// The CLI started in the background (output to a file), to signal it while it runs.
class Child {
public:
    explicit Child(const std::vector<std::string>& arguments, const fs::path& log) {
        std::vector<std::string> all{FRETBUZZ_CLI};
        all.insert(all.end(), arguments.begin(), arguments.end());
        std::vector<char*> argv;
        for (std::string& a : all) argv.push_back(a.data());
        argv.push_back(nullptr);
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        posix_spawn_file_actions_adddup2(&actions, 1, 2);
        if (posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), environ) != 0) pid_ = -1;
        posix_spawn_file_actions_destroy(&actions);
    }
    void signal(int s) const { ::kill(pid_, s); }
    // The exit status, or 128 + the signal that killed it.
    int wait() const {
        int status = 0;
        ::waitpid(pid_, &status, 0);
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }
    pid_t pid() const { return pid_; }

private:
    pid_t pid_ = -1;
};

std::string read_text(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

std::set<std::string> names_in(const fs::path& dir) {
    std::set<std::string> names;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec)) names.insert(e.path().filename().string());
    return names;
}

// A complete result set of one run: summary.json's observation points name exactly the
// WAV files present and the CSV columns, and every file is there and whole.
void expect_complete_set(const fs::path& dir, const std::string& context) {
    SCOPED_TRACE(context);
    const std::set<std::string> names = names_in(dir);
    for (const char* name : {"observation.csv", "energy.csv", "bridge_force.csv", "results.h5", "summary.json"})
        ASSERT_TRUE(names.contains(name)) << name << " missing";
    const auto summary = nlohmann::json::parse(read_text(dir / "summary.json"));
    const auto points = summary["observation_points_m"].get<std::vector<double>>();
    std::set<std::string> wavs;
    for (const std::string& n : names)
        if (n.ends_with(".wav")) wavs.insert(n);
    EXPECT_EQ(wavs.size(), points.size()) << "WAV files of another run beside this summary";
    std::ifstream observation(dir / "observation.csv");
    std::string header;
    std::getline(observation, header);
    EXPECT_EQ(static_cast<std::size_t>(std::count(header.begin(), header.end(), ',')), points.size());
    // The last energy row is whole and the summary's final energy is the state's energy.
    const std::string energy = read_text(dir / "energy.csv");
    ASSERT_FALSE(energy.empty());
    EXPECT_EQ(energy.back(), '\n');
    for (const auto& e : fs::directory_iterator(dir))
        EXPECT_FALSE(e.path().filename().string().starts_with(".fretbuzz")) << e.path();
}

// No staging folder or lock beside or inside the directory.
void expect_no_staging(const fs::path& parent) {
    for (const auto& e : fs::recursive_directory_iterator(parent))
        EXPECT_FALSE(e.path().filename().string().starts_with(".fretbuzz")) << "left behind: " << e.path();
}

const std::vector<std::string> kShortRun = {"run", "bass-pop", "--fs", "400000", "--duration", "0.02", "-q"};

std::vector<std::string> with(std::vector<std::string> base, const std::vector<std::string>& more) {
    base.insert(base.end(), more.begin(), more.end());
    return base;
}

int run_args(const std::vector<std::string>& arguments, const fs::path& log) { return Child(arguments, log).wait(); }

// --- The commit step ----------------------------------------------------------------

TEST(Reliability, StaleFilesOfAnOlderRunAreReplacedAndForeignFilesKept) {
    ScratchDir scratch("stale");
    const fs::path out = scratch.path() / "out";
    const fs::path log = scratch.path() / "log";
    ASSERT_EQ(run_args(with(kShortRun, {"--observe", "0.3", "--velocity-audio", "--out", out.string()}), log), 0)
        << read_text(log);
    ASSERT_TRUE(fs::exists(out / "audio_0.3m.wav"));
    ASSERT_TRUE(fs::exists(out / "velocity_0.3m.wav"));
    std::ofstream(out / "notes.txt") << "my notes";
    ASSERT_EQ(run_args(with(kShortRun, {"--out", out.string()}), log), 0) << read_text(log);
    EXPECT_FALSE(fs::exists(out / "audio_0.3m.wav")) << "a WAV of the older run is left beside the new summary";
    EXPECT_FALSE(fs::exists(out / "velocity_0.3m.wav"));
    EXPECT_FALSE(fs::exists(out / "velocity.wav"));
    EXPECT_EQ(read_text(out / "notes.txt"), "my notes") << "a file fretbuzz never writes must be kept";
    expect_complete_set(out, "second run");
    expect_no_staging(scratch.path());
}

TEST(Reliability, ConcurrentRunsLeaveExactlyOneCompleteSet) {
    ScratchDir scratch("concurrent");
    const fs::path out = scratch.path() / "out";
    for (int trial = 0; trial < 4; ++trial) {
        // Different observation points: a mix of the two runs' files would show.
        Child a(with(kShortRun, {"--observe", "0.3", "--out", out.string()}), scratch.path() / "a.log");
        Child b(with(kShortRun, {"--observe", "0.5", "--observe", "0.6", "--out", out.string()}),
                scratch.path() / "b.log");
        ASSERT_EQ(a.wait(), 0) << read_text(scratch.path() / "a.log");
        ASSERT_EQ(b.wait(), 0) << read_text(scratch.path() / "b.log");
        expect_complete_set(out, "trial " + std::to_string(trial));
        expect_no_staging(scratch.path());
    }
}

// SIGINT and SIGTERM at random moments: exit 130 or 143 and nothing left, or (if the run
// had finished) a complete set; the earlier results are never damaged.
TEST(Reliability, InterruptedRunsLeaveNothingAndKeepEarlierResults) {
    ScratchDir scratch("signals");
    const fs::path earlier = scratch.path() / "earlier";
    const fs::path log = scratch.path() / "log";
    ASSERT_EQ(run_args(with(kShortRun, {"--out", earlier.string()}), log), 0) << read_text(log);
    std::string earlier_summary = read_text(earlier / "summary.json");
    std::string earlier_csv = read_text(earlier / "observation.csv");
    std::mt19937 random(12345);
    const std::vector<std::string> longer = {"run", "bass-pop", "--fs", "1000000", "--duration", "1",
                                             "--observe", "0.4", "-q"};
    for (int trial = 0; trial < 8; ++trial) {
        const int signal = trial % 2 == 0 ? SIGINT : SIGTERM;
        const bool into_earlier = trial % 4 < 2;
        const fs::path fresh = scratch.path() / ("new" + std::to_string(trial));
        const fs::path out = into_earlier ? earlier : fresh / "a" / "b";
        Child child(with(longer, {"--out", out.string()}), log);
        std::this_thread::sleep_for(std::chrono::milliseconds(std::uniform_int_distribution<int>(20, 900)(random)));
        child.signal(signal);
        const int status = child.wait();
        SCOPED_TRACE("trial " + std::to_string(trial) + ": " + read_text(log));
        if (status == 0) {  // finished before the signal: then its set is complete
            expect_complete_set(out, "finished run");
            earlier_summary = read_text(earlier / "summary.json");  // the new earlier results
            earlier_csv = read_text(earlier / "observation.csv");
            continue;
        }
        ASSERT_EQ(status, 128 + signal);
        expect_no_staging(scratch.path());
        if (into_earlier) {
            EXPECT_EQ(read_text(earlier / "summary.json"), earlier_summary);
            EXPECT_EQ(read_text(earlier / "observation.csv"), earlier_csv);
        } else {
            EXPECT_FALSE(fs::exists(fresh)) << "the new --out a/b (or its parents) was left behind";
        }
    }
}

TEST(Reliability, StagingOfAKilledRunIsRemovedByCleanAndByTheNextRun) {
    ScratchDir scratch("sigkill");
    const fs::path out = scratch.path() / "out";
    const fs::path log = scratch.path() / "log";
    for (const bool by_clean : {true, false}) {
        Child child(with({"run", "bass-pop", "--fs", "1000000", "--duration", "1", "-q"}, {"--out", out.string()}), log);
        // Wait until the staging folder exists, then kill without a chance to clean up.
        bool staged = false;
        for (int i = 0; i < 400 && !staged; ++i) {
            std::this_thread::sleep_for(std::chrono::milliseconds(25));
            for (const std::string& n : names_in(scratch.path())) staged = staged || n.starts_with(".fretbuzz-staging");
        }
        child.signal(SIGKILL);
        child.wait();
        ASSERT_TRUE(staged) << read_text(log);
        if (by_clean) {
            const auto result = run_cli("clean " + out.string());
            EXPECT_EQ(result.exit_code, 0) << result.output;
            EXPECT_NE(result.output.find("removed 1"), std::string::npos) << result.output;
        } else {
            ASSERT_EQ(run_args(with(kShortRun, {"--out", out.string()}), log), 0) << read_text(log);
            expect_complete_set(out, "the next run");
        }
        expect_no_staging(scratch.path());
    }
}

// --- Full disk ----------------------------------------------------------------------

class SmallDisk {
public:
    explicit SmallDisk(const fs::path& where) : path_(where) {
        fs::create_directories(path_);
        mounted_ = ::mount("tmpfs", path_.c_str(), "tmpfs", 0, "size=2m") == 0;
    }
    ~SmallDisk() {
        if (mounted_) ::umount(path_.c_str());
    }
    bool mounted() const { return mounted_; }

private:
    fs::path path_;
    bool mounted_ = false;
};

TEST(Reliability, FullDiskExitsOneNamingTheFileAndLeavesEarlierResults) {
    ScratchDir scratch("disk-full");
    const fs::path disk = scratch.path() / "disk";
    SmallDisk small(disk);
    if (!small.mounted()) GTEST_SKIP() << "cannot mount a 2 MiB tmpfs here (needs root): disk-full test skipped";
    const fs::path out = disk / "out";
    const fs::path log = scratch.path() / "log";
    // Earlier results that fit, then runs that fill the disk at different moments.
    const std::vector<std::string> tiny = {"run", "bass-pop", "--fs", "400000", "--duration", "0.005", "-q"};
    ASSERT_EQ(run_args(with(tiny, {"--out", out.string()}), log), 0) << read_text(log);
    const std::string earlier = read_text(out / "summary.json");
    for (const char* duration : {"0.3", "1", "0.5"}) {
        const int status = run_args({"run", "bass-pop", "--duration", duration, "--out", out.string(), "-q"}, log);
        const std::string message = read_text(log);
        SCOPED_TRACE(std::string("duration ") + duration + ": " + message);
        EXPECT_EQ(status, 1) << "a full disk is an I/O failure (exit 1), never a crash";
        EXPECT_NE(message.find(disk.string()), std::string::npos) << "the message must name the file";
        EXPECT_EQ(read_text(out / "summary.json"), earlier);
        expect_no_staging(disk);
        EXPECT_EQ(names_in(disk), std::set<std::string>{"out"});
    }
}

// --- Exit codes and validation ------------------------------------------------------

TEST(Reliability, CommandLineParseErrorsExitTwo) {
    for (const char* arguments :
         {"run bass-pop --fs abc", "run bass-pop --no-such-option", "run", "run bass-pop --fs", "no-such-command",
          "run bass-pop --duration 1 2 3", "convergence bass-pop --window x"}) {
        const auto result = run_cli(arguments);
        EXPECT_EQ(result.exit_code, 2) << arguments << ": " << result.output;
    }
    EXPECT_EQ(run_cli("--help").exit_code, 0);
    EXPECT_EQ(run_cli("--version").exit_code, 0);
}

TEST(Reliability, DerivedQuantitiesAreCheckedBeforeTheRun) {
    ScratchDir scratch("derived");
    const std::string pluck = run_cli("show bass-pluck").output;
    const auto with_line = [&](const std::string& name, const std::string& from, const std::string& to) {
        std::string text = pluck;
        const auto at = text.find(from);
        EXPECT_NE(at, std::string::npos) << from;
        text.replace(at, from.size(), to);
        std::ofstream(scratch.path() / name) << text;
        return (scratch.path() / name).string();
    };
    struct Refused {
        std::string arguments, must_mention;
    };
    const std::string mu_line = pluck.substr(pluck.find("mu = "), pluck.find('\n', pluck.find("mu = ")) - pluck.find("mu = "));
    const Refused cases[] = {
        {with_line("heavy.toml", mu_line, "mu = 1e300"), "string.mu"},
        {"bass-pop --alpha 1e4", "contact.alpha"},
        {"bass-pop --duration 1e-9", "run.duration"},
        // sigma of the top modes * dt: above the limit at 10 Hz sampling (no obstacle: no aliasing check).
        {"bass-pluck --fs 10 --duration 1", "sigma_per_s"},
    };
    for (const Refused& r : cases) {
        const fs::path out = scratch.path() / "out";
        const auto result = run_cli("run " + r.arguments + " --out " + out.string() + " -q");
        EXPECT_EQ(result.exit_code, 2) << r.arguments << ": " << result.output;
        EXPECT_NE(result.output.find(r.must_mention), std::string::npos) << r.arguments << ": " << result.output;
        EXPECT_FALSE(fs::exists(out));
    }
}

// --- Strings on a bridge: bounded and streamed as a one-string run ------------------

// Two pair-strings on one bridge mode, with `run_extra` added to its [run]: the case's path.
fs::path two_strings_case(const ScratchDir& scratch, const std::string& duration, const std::string& run_extra) {
    fs::copy_file(fs::path(FRETBUZZ_SOURCE_DIR) / "cases/bridges/pair-string.toml", scratch.path() / "p.toml",
                  fs::copy_options::overwrite_existing);
    // A file of its own for each, so that several can be written before any is run.
    const fs::path path = scratch.path() / ("s-" + std::to_string(std::hash<std::string>{}(duration + run_extra)) + ".toml");
    std::ofstream(path) << "name = \"x\"\n[run]\nfs = 96000\nduration = " << duration << "\n" << run_extra
                        << "\n[bridge]\n[[bridge.mode]]\nmass_kg = 0.005\nfrequency_hz = 300.0\nparticipation = [1.0, 1.0]\n"
                           "[[string]]\nname = \"a\"\ncase = \"p.toml\"\n[[string]]\nname = \"b\"\ncase = \"p.toml\"\n";
    return path;
}

// The run's length and rates are checked as a one-string run's are, after every override and
// before anything is written: audio_rate 1e300 crashed libsoxr, 1e-300 and 1e12 spun, 3e9
// took gigabytes; --duration 1e300 ran "-9223372036854775808 steps", 1e-7 ran none, 1e5 ran
// 9.6e9 steps.
TEST(Reliability, StringsRunLengthAndRatesAreBoundedAfterEveryOverride) {
    const ScratchDir scratch("strings-bounds");
    const fs::path out = scratch.path() / "out";
    struct Refused {
        std::string arguments, must_mention;
    };
    std::vector<Refused> refused;
    for (const char* rate : {"1e300", "1e-300", "1e12", "3e9", "1e7", "1", "7999"})
        refused.push_back({two_strings_case(scratch, "0.05", std::string("audio_rate = ") + rate).string(), "run.audio_rate"});
    refused.push_back({two_strings_case(scratch, "0.05", "output_rate = 1e6").string(), "run.output_rate"});
    for (const char* duration : {"1e300", "1e-7", "1e5"})
        refused.push_back({std::string("strings-on-a-bridge --duration ") + duration, "number of steps"});
    refused.push_back({"strings-on-a-bridge --audio-rate 1e300", "run.audio_rate"});
    refused.push_back({"strings-on-a-bridge --fs 1e12", "number of steps"});
    refused.push_back({"strings-on-a-bridge --output-rate 1e9", "run.output_rate"});
    // An option a strings case does not take is named rather than ignored.
    refused.push_back({"strings-on-a-bridge --K 1e12 --duration 0.01", "--K"});
    // The same bound below for one string: no run of no step.
    refused.push_back({"bass-pop --duration 1e-7", "number of steps"});
    for (const Refused& r : refused) {
        const auto started = std::chrono::steady_clock::now();
        const auto result = run_cli("run " + r.arguments + " --out " + out.string() + " -q");
        EXPECT_EQ(result.exit_code, 2) << r.arguments << ": " << result.output;
        EXPECT_NE(result.output.find(r.must_mention), std::string::npos) << r.arguments << ": " << result.output;
        EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count(), 10.0) << r.arguments;
        EXPECT_FALSE(fs::exists(out)) << r.arguments;
    }
    // What the bounds allow runs: the shortest run (one step) and the outer audio rates (at
    // 384 kHz without bridge.ogg, which Vorbis does not encode: it failed the run after computing).
    for (const std::string& arguments : {two_strings_case(scratch, "1.05e-5", "audio_rate = 8000").string(),
                                        two_strings_case(scratch, "0.002", "audio_rate = 384000").string()}) {
        const auto result = run_cli("run " + arguments + " --out " + out.string() + " -q");
        EXPECT_EQ(result.exit_code, 0) << arguments << ": " << result.output;
    }
    EXPECT_EQ(nlohmann::json::parse(read_text(out / "summary.json"))["steps"], 192);
    EXPECT_TRUE(fs::is_regular_file(out / "bridge.wav"));
    EXPECT_FALSE(fs::exists(out / "bridge.ogg"));
}

long resident_kb(pid_t pid) {
    std::ifstream status("/proc/" + std::to_string(pid) + "/status");
    std::string line;
    while (std::getline(status, line))
        if (line.starts_with("VmRSS:")) return std::stol(line.substr(6));
    return -1;
}

// A strings run writes its rows and its sound as they come: its memory stays flat however
// long it runs (it grew some 50 MB per second of computing at a row per step), and Ctrl-C
// leaves nothing.
TEST(Reliability, AStringsRunStreamsItsRowsAndSound) {
    const ScratchDir scratch("strings-stream");
    const fs::path out = scratch.path() / "out";
    const Child run({"run", two_strings_case(scratch, "41666", "output_rate = 96000").string(), "--out", out.string(), "-q"},
                    scratch.path() / "log");
    std::this_thread::sleep_for(std::chrono::seconds(2));
    const long first = resident_kb(run.pid());
    std::this_thread::sleep_for(std::chrono::seconds(3));
    const long second = resident_kb(run.pid());
    run.signal(SIGINT);
    EXPECT_EQ(run.wait(), 130) << read_text(scratch.path() / "log");
    ASSERT_GT(first, 0);
    std::printf("a strings run at a row per step: resident %.1f MB at 2 s, %.1f MB at 5 s\n", static_cast<double>(first) / 1024.0,
                static_cast<double>(second) / 1024.0);
    EXPECT_LT(second - first, 8 * 1024) << "rows or sound kept in memory";
    EXPECT_FALSE(fs::exists(out));
    expect_no_staging(scratch.path());
}

// The streamed files are those of the run kept in memory: strings.csv row for row, every WAV
// file byte for byte as write_normalised_audio makes it of the whole signal; the summary names
// the balance as a one-string run's does.
TEST(Reliability, AStringsRunsStreamedFilesAreThoseOfTheRunKeptInMemory) {
    const ScratchDir scratch("strings-files");
    const fs::path out = scratch.path() / "out";
    const fs::path path = two_strings_case(scratch, "0.3", "output_rate = 12000");
    const auto result = run_cli("run " + path.string() + " --out " + out.string() + " -q");
    ASSERT_EQ(result.exit_code, 0) << result.output;
    const StringsCase sc = parse_strings_case(*read_strings_case_text(path.string()));
    const StringsRun kept = simulate_strings(sc);
    std::string csv = "t,a,b,bridge,balance\n";
    for (std::size_t r = 0; r < kept.t.size(); ++r) {
        for (const double v : {kept.t[r], kept.energy[0][r], kept.energy[1][r], kept.bridge_energy[r], kept.balance[r]}) {
            append_number(csv, v);
            csv += ',';
        }
        csv.back() = '\n';
    }
    EXPECT_EQ(read_text(out / "strings.csv"), csv);
    const struct {
        const char* file;
        const std::vector<double>& signal;
    } sounds[] = {{"bridge.wav", kept.bridge_audio}, {"pickup_a.wav", kept.pickup_audio[0]}, {"pickup_b.wav", kept.pickup_audio[1]}};
    for (const auto& s : sounds) {
        ASSERT_GT(s.signal.size(), 14000u);  // 0.3 s at 48 kHz
        write_normalised_audio(scratch.path() / s.file, s.signal, kept.audio_rate_hz);
        EXPECT_EQ(read_text(out / s.file), read_text(scratch.path() / s.file)) << s.file;
    }
    const auto summary = nlohmann::json::parse(read_text(out / "summary.json"));
    EXPECT_EQ(summary["max_relative_energy_increase"], kept.max_relative_energy_increase);
    EXPECT_EQ(summary["max_relative_energy_balance_error"], kept.max_relative_balance_error);
    EXPECT_LT(kept.max_relative_balance_error, 1e-11);  // the balance to round-off, damping included
    EXPECT_FALSE(summary.contains("worst_relative_balance"));
    EXPECT_EQ(names_in(out), (std::set<std::string>{"strings.csv", "bridge.wav", "bridge.ogg", "pickup_a.wav",
                                                    "pickup_b.wav", "case.toml", "summary.json"}));
}

// A state gone to infinity or NaN stops the run (SolverError: exit 3) naming the first bad
// quantity; before, NaN slipped through std::max and the summary reported a 0 balance error.
TEST(Reliability, NonFiniteStateStopsTheRunNamingTheQuantity) {
    Case c = load_case("bass-pop");
    c.run.sample_rate_hz = 400000.0;
    c.run.duration_s = 0.002;
    c.run.allow_aliasing = true;
    c.initial_displacement.assign(c.mode_count(), 0.0);
    c.initial_velocity.assign(c.mode_count(), 0.0);
    c.initial_velocity[0] = -1e148;  // finite energy (1e293 J), but the contact energy overflows
    c.validate();
    try {
        simulate(c, {});
        FAIL() << "the run should have stopped";
    } catch (const SolverError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("non-finite value"), std::string::npos) << message;
        EXPECT_NE(message.find("contact energy"), std::string::npos) << "names the first bad quantity: " << message;
    }
}

// The summary's final energy is the state's at the last step, not the last output row's:
// at an output rate below 1/duration the only row is the first one.
TEST(Reliability, SummaryEnergyComesFromTheFinalState) {
    ScratchDir scratch("final-energy");
    const fs::path native = scratch.path() / "native", sparse = scratch.path() / "sparse";
    const std::vector<std::string> base = {"run", "bass-pop", "--fs", "400000", "--duration", "0.02", "-q"};
    ASSERT_EQ(run_args(with(base, {"--output-rate", "native", "--out", native.string()}), scratch.path() / "log"), 0);
    ASSERT_EQ(run_args(with(base, {"--output-rate", "10", "--out", sparse.string()}), scratch.path() / "log"), 0);
    const auto a = nlohmann::json::parse(read_text(native / "summary.json"));
    const auto b = nlohmann::json::parse(read_text(sparse / "summary.json"));
    ASSERT_GT(a["contact_steps"].get<long>(), 0) << "the test needs contacts, which dissipate nothing but move energy";
    const double final_native = a["energy_final_J"].get<double>(), final_sparse = b["energy_final_J"].get<double>();
    EXPECT_NE(final_sparse, b["energy_initial_J"].get<double>());
    EXPECT_NEAR(final_sparse, final_native, 1e-9 * std::abs(final_native));
    // And the balance closes on it: H_final + dissipated = H_initial.
    EXPECT_NEAR(final_sparse + b["dissipated_J"].get<double>(), b["energy_initial_J"].get<double>(),
                1e-9 * b["energy_initial_J"].get<double>());
}

// --- Data files read as someone else's input ----------------------------------------

class HostileFiles : public ::testing::Test {
protected:
    void SetUp() override {
        const std::string pluck = run_cli("show bass-pluck").output;
        const std::string key = "table = \"";
        const auto at = pluck.find(key);
        ASSERT_NE(at, std::string::npos);
        const auto end = pluck.find('"', at + key.size());
        table_name_ = pluck.substr(at + key.size(), end - at - key.size());
        case_text_ = pluck;
    }
    // A case whose mode table is `table` (a path), and the result of running it.
    testing::CommandResult run_with_table(const std::string& table) {
        std::string text = case_text_;
        text.replace(text.find(table_name_), table_name_.size(), table);
        std::ofstream(scratch_.path() / "case.toml") << text;
        return run_cli("run " + (scratch_.path() / "case.toml").string() + " --out " + out().string() + " -q");
    }
    fs::path out() const { return scratch_.path() / "out"; }
    ScratchDir scratch_{"hostile"};
    std::string case_text_, table_name_;
};

TEST_F(HostileFiles, SpecialFilesAreRefusedWithoutReadingThem) {
    const fs::path fifo = scratch_.path() / "fifo";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    const auto start = std::chrono::steady_clock::now();
    for (const std::string& path : {fifo.string(), std::string("/dev/zero"), scratch_.path().string()}) {
        const auto result = run_with_table(path);
        EXPECT_EQ(result.exit_code, 2) << path << ": " << result.output;
        EXPECT_NE(result.output.find("not a regular file"), std::string::npos) << result.output;
        EXPECT_NE(result.output.find("modes.table"), std::string::npos) << "names the key: " << result.output;
        EXPECT_FALSE(fs::exists(out()));
    }
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 30.0);
}

TEST_F(HostileFiles, SizeAndLineLengthAreBoundedAndContentNeverEchoed) {
    const fs::path big = scratch_.path() / "big.csv";
    { std::ofstream(big) << "1,100,1\n"; }
    fs::resize_file(big, 65u << 20);  // sparse: costs no disk
    auto result = run_with_table(big.string());
    EXPECT_EQ(result.exit_code, 2) << result.output;
    EXPECT_NE(result.output.find("larger than"), std::string::npos) << result.output;

    const fs::path wide = scratch_.path() / "wide.csv";
    std::ofstream(wide) << "1,100,1\n2," << std::string(100000, '9') << ",1\n";
    result = run_with_table(wide.string());
    EXPECT_EQ(result.exit_code, 2) << result.output;
    EXPECT_NE(result.output.find("wide.csv:2: the line is longer than"), std::string::npos) << result.output;

    const fs::path secret = scratch_.path() / "secret.csv";
    std::ofstream(secret) << "1,100,1\nroot:SECRET-PASSWORD-HASH:0:0\n";
    result = run_with_table(secret.string());
    EXPECT_EQ(result.exit_code, 2) << result.output;
    EXPECT_NE(result.output.find("secret.csv:2"), std::string::npos) << "file and line: " << result.output;
    EXPECT_EQ(result.output.find("SECRET"), std::string::npos) << "the file's content was echoed: " << result.output;
}

TEST_F(HostileFiles, OverlongFileNamesExitTwoNamingTheKey) {
    const auto result = run_with_table(std::string(300, 'x') + ".csv");
    EXPECT_EQ(result.exit_code, 2) << result.output;
    EXPECT_NE(result.output.find("modes.table"), std::string::npos) << result.output;
    EXPECT_NE(result.output.find("255"), std::string::npos) << result.output;
    const auto out = run_cli("run bass-pop --out " + (scratch_.path() / std::string(300, 'y')).string() + " -q");
    EXPECT_EQ(out.exit_code, 2) << out.output;
    EXPECT_NE(out.output.find("--out"), std::string::npos) << out.output;
}

TEST_F(HostileFiles, DeepTomlIsRefusedBeforeParsing) {
    std::string header = "[a";
    for (int i = 0; i < 50000; ++i) header += ".a";
    header += "]\n";
    std::string nested = "x = " + std::string(5000, '[') + std::string(5000, ']') + "\n";
    for (const std::string& text : {header, nested, case_text_ + "\n" + header}) {
        std::ofstream(scratch_.path() / "deep.toml") << text;
        const auto result = run_cli("run " + (scratch_.path() / "deep.toml").string() + " --out " + out().string() + " -q");
        EXPECT_EQ(result.exit_code, 2) << result.output.substr(0, 300);
        EXPECT_NE(result.output.find("deep.toml:"), std::string::npos) << result.output.substr(0, 300);
        EXPECT_FALSE(fs::exists(out()));
    }
}

}  // namespace
}  // namespace fretbuzz
