// Sweeps: expansion of a spec into runs, values checked by the case-file parser, rows
// equal to single runs of the same parameters, resumption, and refusals of bad specs.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>

#include <chrono>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <filesystem>
#include <regex>
#include <string>
#include <thread>

#include "SweepTestCases.hpp"
#include "TestSupport.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/analysis/BuzzMetrics.hpp"
#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/sweep/Sweep.hpp"
#include "fretbuzz/sweep/SweepStore.hpp"

namespace fretbuzz {
namespace {

using testing::read_text;
using testing::ScratchDir;
using testing::write_text;

struct SweepFixture {
    ScratchDir dir{"sweep"};
    SweepFixture() { write_text(dir.path() / "note.toml", testing::note_case_text()); }
    SweepSpec spec(const std::string& body) const {
        const std::string text = "[sweep]\ncase = \"note.toml\"\n" + body;
        write_text(dir.path() / "spec.toml", text);
        return load_sweep(dir.path() / "spec.toml");
    }
};

std::size_t metric(const std::string& name) {
    const auto& names = sweep_metric_names();
    return static_cast<std::size_t>(std::find(names.begin(), names.end(), name) - names.begin());
}

TEST(Sweep, GridExpandsEveryCombinationLastParameterFastest) {
    SweepFixture f;
    const SweepSpec spec = f.spec(
        "[[parameter]]\nkey = \"contact.K\"\nvalues = [1e9, 1e11]\n"
        "[[parameter]]\nkey = \"run.fs\"\nfrom = 2e5\nto = 8e5\ncount = 3\nscale = \"log\"\n");
    ASSERT_EQ(spec.runs.size(), 6u);
    EXPECT_EQ(spec.parameter_keys, (std::vector<std::string>{"contact.K", "run.fs"}));
    EXPECT_EQ(spec.runs[1].values[0].text, "1e+09");
    EXPECT_EQ(spec.runs[1].values[1].text, "400000");  // log midpoint of 2e5 and 8e5
    EXPECT_EQ(spec.runs[5].values[0].text, "1e+11");
    EXPECT_EQ(spec.runs[5].values[1].text, "800000");
    const Case c = sweep_case(spec, spec.runs[4]);
    EXPECT_EQ(c.contact.stiffness, 1e11);
    EXPECT_EQ(c.run.sample_rate_hz, 400000.0);
}

TEST(Sweep, ZipTakesTheKthValuesTogether) {
    SweepFixture f;
    const SweepSpec spec = f.spec(
        "combine = \"zip\"\n[set]\nrun.duration = 0.005\n"
        "[[parameter]]\nkey = \"contact.K\"\nvalues = [1e9, 1e11]\n"
        "[[parameter]]\nkey = \"contact.alpha\"\nvalues = [1, 2]\n");
    ASSERT_EQ(spec.runs.size(), 2u);
    const Case c = sweep_case(spec, spec.runs[1]);
    EXPECT_EQ(c.contact.stiffness, 1e11);
    EXPECT_EQ(c.contact.exponent, 2.0);
    EXPECT_EQ(c.run.duration_s, 0.005);  // [set], written as a nested table
}

// Each row's metrics are those of a single run of the same case with the value set
// directly on the Case: bit for bit.
TEST(Sweep, RowsEqualSingleRunsOverKAndFs) {
    SweepFixture f;
    const SweepSpec spec = f.spec(
        "[[parameter]]\nkey = \"contact.K\"\nvalues = [1e9, 1e11]\n"
        "[[parameter]]\nkey = \"run.fs\"\nvalues = [200000, 400000]\n");
    const ScratchDir out("sweep-out");
    SweepOptions options;
    options.jobs = 2;
    const SweepOutcome outcome = run_sweep(spec, out.path() / "s", options);
    EXPECT_EQ(outcome.computed, 4u);
    const SweepStore store(spec, out.path() / "s", true);
    const std::vector<SweepRow> rows = store.rows();
    ASSERT_EQ(rows.size(), 4u);
    for (const SweepRow& row : rows) {
        ASSERT_TRUE(row.ok) << row.error;
        Case c = load_case((f.dir.path() / "note.toml").string());
        c.contact.stiffness = std::stod(row.values[0]);
        c.run.sample_rate_hz = std::stod(row.values[1]);
        BuzzMetrics metrics(spec.buzz_band_hz);
        RunObserver* observers[] = {&metrics};
        const RunSummary summary = simulate(c, observers);
        const BuzzReport& b = metrics.report();
        // The buzz level: what the contacts added to the signal, against the same run
        // with no obstacle, in the buzz band.
        Case free_case = c;
        free_case.obstacle_height_m.assign(c.obstacle_height_m.size(), -std::numeric_limits<double>::infinity());
        BuzzMetrics free_metrics(spec.buzz_band_hz);
        RunObserver* free_observers[] = {&free_metrics};
        simulate(free_case, free_observers);
        std::vector<double> added = metrics.signal();
        for (std::size_t i = 0; i < added.size(); ++i) added[i] -= free_metrics.signal()[i];
        const double e_added = high_frequency_energy(added, summary.output_rate_hz, spec.buzz_band_hz);
        const double e_free = free_metrics.report().high_frequency_energy;
        EXPECT_EQ(row.metrics[metric("hf_energy_free_m2")], e_free);
        EXPECT_EQ(row.metrics[metric("hf_energy_contact_m2")], e_added);
        EXPECT_EQ(row.metrics[metric("buzz_dB")], 10.0 * std::log10(e_added / e_free));
        EXPECT_GT(b.contact_steps, 0);
        EXPECT_EQ(row.metrics[metric("contact_steps")], static_cast<double>(b.contact_steps));
        EXPECT_EQ(row.metrics[metric("peak_contact_force_N")], b.peak_force_n);
        EXPECT_EQ(row.metrics[metric("contact_impulse_Ns")], b.impulse_n_s);
        EXPECT_EQ(row.metrics[metric("hf_energy_m2")], b.high_frequency_energy);
        EXPECT_EQ(row.metrics[metric("first_contact_s")], b.first_contact_s);
        EXPECT_EQ(row.metrics[metric("energy_final_J")], summary.energy_final_j);
    }
    // The table lists the values as written and the metrics in full precision.
    const std::string csv = read_text(out.path() / "s" / "results.csv");
    EXPECT_NE(csv.find("run,contact.K,run.fs,status,error,features,contact_steps"), std::string::npos);
    EXPECT_NE(csv.find("\n3,1e+11,400000,ok,,1,"), std::string::npos);
    EXPECT_TRUE(std::filesystem::exists(out.path() / "s" / "results.h5"));
}

TEST(Sweep, ResumeRunsOnlyTheMissingRowsAndGivesTheSameTable) {
    SweepFixture f;
    const SweepSpec spec = f.spec("[[parameter]]\nkey = \"contact.K\"\nvalues = [1e8, 1e9, 1e10, 1e11]\n");
    const ScratchDir out("sweep-resume");
    const auto dir = out.path() / "s";
    run_sweep(spec, dir);
    const std::string table = read_text(dir / "results.csv");
    // As if interrupted after two runs: two row files and no table.
    std::filesystem::remove(dir / "runs" / "000001.json");
    std::filesystem::remove(dir / "runs" / "000003.json");
    std::filesystem::remove(dir / "results.csv");
    EXPECT_THROW(run_sweep(spec, dir), InputError);  // --resume is needed
    SweepOptions options;
    options.resume = true;
    std::size_t calls = 0, resumed = 0;
    options.progress = [&](const SweepProgress& p) {
        ++calls;
        resumed = p.resumed;
        EXPECT_EQ(p.total, 4u);
    };
    const SweepOutcome outcome = run_sweep(spec, dir, options);
    EXPECT_EQ(outcome.computed, 2u);
    EXPECT_EQ(outcome.resumed, 2u);
    EXPECT_EQ(calls, 2u);
    EXPECT_EQ(resumed, 2u);
    EXPECT_EQ(read_text(dir / "results.csv"), table);
    // A different spec cannot resume into this directory.
    const SweepSpec other = f.spec("[[parameter]]\nkey = \"contact.K\"\nvalues = [1e8]\n");
    EXPECT_THROW(run_sweep(other, dir, options), InputError);
}

// Asked to stop (Ctrl-C from Python), a sweep finishes the runs under way, keeps their
// rows, writes no table, and a resumed sweep completes it with the same table.
TEST(Sweep, AStoppedSweepKeepsItsRowsAndResumes) {
    SweepFixture f;
    const SweepSpec spec = f.spec("[[parameter]]\nkey = \"contact.K\"\nvalues = [1e8, 1e9, 1e10, 1e11]\n");
    const ScratchDir out("sweep-stop");
    run_sweep(spec, out.path() / "whole");
    SweepOptions options;
    options.jobs = 1;
    std::size_t finished = 0;
    options.progress = [&](const SweepProgress&) { ++finished; };
    options.stop = [&] { return finished >= 2; };
    const SweepOutcome stopped = run_sweep(spec, out.path() / "s", options);
    EXPECT_TRUE(stopped.interrupted);
    EXPECT_EQ(stopped.computed, 2u);
    EXPECT_FALSE(std::filesystem::exists(out.path() / "s" / "results.csv"));
    SweepOptions resume;
    resume.resume = true;
    const SweepOutcome rest = run_sweep(spec, out.path() / "s", resume);
    EXPECT_FALSE(rest.interrupted);
    EXPECT_EQ(rest.computed, 2u);
    EXPECT_EQ(rest.resumed, 2u);
    EXPECT_EQ(read_text(out.path() / "s" / "results.csv"), read_text(out.path() / "whole" / "results.csv"));
}

TEST(Sweep, AFailedRunStaysInTheTableWithItsError) {
    SweepFixture f;
    const SweepSpec spec = f.spec("[[parameter]]\nkey = \"contact.K\"\nvalues = [1e9, 1e10]\n");
    const ScratchDir out("sweep-failed");
    // The run's audio folder cannot be created (a file is in the way): the run fails.
    write_text(out.path() / "blocker", "x");
    const SweepRow failed = run_sweep_point(spec, 1, out.path() / "blocker" / "audio");
    EXPECT_FALSE(failed.ok);
    EXPECT_FALSE(failed.error.empty());
    const SweepStore store(spec, out.path() / "s", false);
    store.record(run_sweep_point(spec, 0));
    store.record(failed);
    store.write_table();
    const std::string csv = read_text(out.path() / "s" / "results.csv");
    EXPECT_NE(csv.find("\n0,1e+09,ok,"), std::string::npos);
    EXPECT_NE(csv.find("\n1,1e+10,failed,"), std::string::npos);
    const SweepRow back = row_from_json(row_to_json(failed));
    EXPECT_EQ(back.error, failed.error);
    EXPECT_TRUE(std::isnan(back.metrics[0]));
}

void expect_refused(const SweepFixture& f, const std::string& body, const std::string& named) {
    const ScratchDir out("sweep-bad");
    try {
        const SweepSpec spec = f.spec(body);
        run_sweep(spec, out.path() / "s");
        ADD_FAILURE() << "accepted: " << body;
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(named), std::string::npos) << e.what();
    }
    EXPECT_FALSE(std::filesystem::exists(out.path() / "s")) << "wrote output for a bad spec";
}

TEST(Sweep, BadSpecsAreRefusedNamingTheKeyAndWriteNothing) {
    SweepFixture f;
    expect_refused(f, "[[parameter]]\nkey = \"contact.Kx\"\nvalues = [1e9]\n", "contact.Kx");
    expect_refused(f, "[[parameter]]\nkey = \"contact.K\"\nvalues = []\n", "empty");
    expect_refused(f, "[[parameter]]\nkey = \"contact.K\"\nvalues = [1e9, -1.0]\n", "contact.K");
    expect_refused(f, "[[parameter]]\nkey = \"contact.alpha\"\nvalues = [0.5]\n", "contact.alpha");
    expect_refused(f, "[[parameter]]\nkey = \"string.modes\"\nvalues = [10.5]\n", "string.modes");
    expect_refused(f, "[[parameter]]\nkey = \"contact.K\"\nvalues = [1e9]\ntypo = 1\n", "parameter[0].typo");
    expect_refused(f, "[[parameter]]\nkey = \"contact.K.x\"\nvalues = [1e9]\n", "contact.K.x");
    expect_refused(f, "[set]\nrun.fss = 1e5\n", "run.fss");
}

TEST(SweepCommand, RunsAndRefusesABadSpecWithExitStatus2) {
    SweepFixture f;
    const ScratchDir out("sweep-cli");
    f.spec("[[parameter]]\nkey = \"contact.K\"\nvalues = [1e9, 1e10]\n");
    const std::string spec = (f.dir.path() / "spec.toml").string();
    const auto good = testing::run_cli("sweep " + spec + " --jobs 2 --quiet --out " + (out.path() / "a").string());
    EXPECT_EQ(good.exit_code, 0) << good.output;
    EXPECT_TRUE(std::filesystem::exists(out.path() / "a" / "results.csv"));
    const auto again = testing::run_cli("sweep " + spec + " --quiet --out " + (out.path() / "a").string());
    EXPECT_EQ(again.exit_code, 2) << again.output;
    EXPECT_NE(again.output.find("--resume"), std::string::npos);

    f.spec("[[parameter]]\nkey = \"contact.Q\"\nvalues = [1e9]\n");
    const auto bad = testing::run_cli("sweep " + spec + " --out " + (out.path() / "b").string());
    EXPECT_EQ(bad.exit_code, 2) << bad.output;
    EXPECT_NE(bad.output.find("contact.Q"), std::string::npos) << bad.output;
    EXPECT_FALSE(std::filesystem::exists(out.path() / "b"));
}

// Every *.tmp-* file under dir (what an interrupted atomic write leaves).
std::vector<std::string> temporaries(const std::filesystem::path& dir) {
    std::vector<std::string> found;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(dir))
        if (entry.path().filename().string().find(".tmp-") != std::string::npos)
            found.push_back(entry.path().string());
    return found;
}

// Sweeps are read by the input floor: the sweep floor edits no TOML (the spec's values are
// set in the base case's parsed document there, then read by the case reader).
TEST(SweepSpec, TomlIsReadInTheInputFloorOnly) {
    const std::filesystem::path root(FRETBUZZ_SOURCE_DIR);
    const std::regex toml_use(R"(toml\+\+|TomlSection|parse_toml_document|toml::)");
    for (const auto& dir : {root / "src" / "sweep", root / "include" / "fretbuzz" / "sweep"})
        for (const auto& entry : std::filesystem::directory_iterator(dir))
            EXPECT_FALSE(std::regex_search(read_text(entry.path()), toml_use))
                << entry.path() << " reads or edits TOML: sweep specs and cases are read in src/input";
}

// The values keep their TOML type through the parsed document: a string, an array and an
// inline table set as they would be in the case file, and the run's case records the
// edited document as its text.
TEST(SweepSpec, ValuesOfEveryTypeAreSetInTheParsedCase) {
    SweepFixture f;
    const SweepSpec spec = f.spec(
        "[set]\nobserve.x = [0.3, 0.55]\nname = \"edited\"\n"
        "[[parameter]]\nkey = \"contact.alpha\"\nvalues = [1, 2.5]\n");
    const Case c = sweep_case(spec, spec.runs[1]);
    EXPECT_EQ(c.name, "edited");
    EXPECT_EQ(c.observation_points_m, (std::vector<double>{0.3, 0.55}));
    EXPECT_EQ(c.contact.exponent, 2.5);
    EXPECT_NE(c.source_text.find("alpha = 2.5"), std::string::npos) << c.source_text;
    EXPECT_EQ(parse_case(c.source_text, "again", DataSource::builtin()).contact.exponent, 2.5);
}

// A grid is counted before any run is made: 1e5 x 1e5 runs is refused at once (it used to
// run out of memory), naming the lists and the option that raises the limit; under the
// limit a large grid holds its lists, not its runs, and makes any run from its index.
TEST(SweepSpec, AGridPastTheRunLimitIsRefusedBeforeAnyRunIsMade) {
    SweepFixture f;
    const std::string huge =
        "[[parameter]]\nkey = \"contact.K\"\nfrom = 1e8\nto = 1e12\ncount = 100000\n"
        "[[parameter]]\nkey = \"run.fs\"\nfrom = 2e5\nto = 8e5\ncount = 100000\n";
    const auto start = std::chrono::steady_clock::now();
    try {
        f.spec(huge);
        ADD_FAILURE() << "a grid of 1e10 runs was accepted";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("100000 (contact.K) x 100000 (run.fs)"), std::string::npos) << what;
        EXPECT_NE(what.find(std::to_string(kDefaultMaxSweepRuns)), std::string::npos) << what;
        EXPECT_NE(what.find("--max-runs"), std::string::npos) << what;
    }
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 30.0);

    write_text(f.dir.path() / "big.toml", "[sweep]\ncase = \"note.toml\"\n" +
                                              std::string("[[parameter]]\nkey = \"contact.K\"\nfrom = 1e8\nto = "
                                                          "1e12\ncount = 1000\n[[parameter]]\nkey = \"run.fs\"\n"
                                                          "from = 2e5\nto = 8e5\ncount = 1000\n"));
    EXPECT_THROW(load_sweep(f.dir.path() / "big.toml"), InputError);
    const SweepSpec big = load_sweep(f.dir.path() / "big.toml", 1000000);
    ASSERT_EQ(big.runs.size(), 1000000u);
    const SweepRun last = big.runs[999999];
    EXPECT_EQ(last.values[0].text, "1e+12");
    EXPECT_EQ(last.values[1].text, "800000");
    EXPECT_EQ(big.runs[1000].values[0].text, big.runs[1999].values[0].text);
    EXPECT_EQ(sweep_case(big, big.runs[999]).run.sample_rate_hz, 8e5);
    EXPECT_THROW(big.runs[1000000], InputError);
    EXPECT_THROW(load_sweep(f.dir.path() / "big.toml", 0), InputError);

    // The command line: exit 2, nothing written; --max-runs raises the limit.
    const ScratchDir out("sweep-limit");
    const std::string spec = (f.dir.path() / "big.toml").string();
    const auto refused = testing::run_cli("sweep " + spec + " --quiet --out " + (out.path() / "a").string());
    EXPECT_EQ(refused.exit_code, 2) << refused.output;
    EXPECT_NE(refused.output.find("--max-runs"), std::string::npos) << refused.output;
    EXPECT_FALSE(std::filesystem::exists(out.path() / "a"));
}

// Checking every run's case reports its progress (the command prints it) and, on several
// threads, still names the lowest failing run.
TEST(SweepSpec, CheckingReportsProgressAndTheFirstBadRun) {
    SweepFixture f;
    const SweepSpec spec = f.spec("[[parameter]]\nkey = \"contact.K\"\nfrom = 1e8\nto = 1e10\ncount = 40\n");
    std::vector<std::size_t> seen;
    check_sweep(spec, [&](std::size_t checked, std::size_t total) {
        EXPECT_EQ(total, 40u);
        seen.push_back(checked);
    }, 3);
    ASSERT_EQ(seen.size(), 40u);
    for (std::size_t k = 0; k < seen.size(); ++k) EXPECT_EQ(seen[k], k + 1);

    const SweepSpec bad = f.spec(
        "[[parameter]]\nkey = \"contact.alpha\"\nvalues = [1.5, 0.5, 0.25]\n"
        "[[parameter]]\nkey = \"contact.K\"\nfrom = 1e8\nto = 1e10\ncount = 20\n");
    for (unsigned jobs : {1u, 4u}) {
        try {
            check_sweep(bad, {}, jobs);
            ADD_FAILURE() << "accepted alpha = 0.5";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find("run 20 (contact.alpha = 0.5"), std::string::npos) << e.what();
        }
    }
}

// A full disk (here: a file-size limit) while a row is written: the error says why (the
// system's text), and no temporary file is left behind.
TEST(SweepStore, AFailedWriteSaysWhyAndLeavesNoTemporaryFile) {
    SweepFixture f;
    const SweepSpec spec = f.spec("[[parameter]]\nkey = \"contact.K\"\nvalues = [1e9, 1e10]\n");
    const ScratchDir out("sweep-full");
    const SweepStore store(spec, out.path() / "s", false);
    const SweepRow row = run_sweep_point(spec, 0);
    struct rlimit before {};
    ::getrlimit(RLIMIT_FSIZE, &before);
    struct sigaction ignore {}, previous {};
    ignore.sa_handler = SIG_IGN;
    ::sigaction(SIGXFSZ, &ignore, &previous);
    struct rlimit small = before;
    small.rlim_cur = 16;  // bytes: every row file is longer
    ::setrlimit(RLIMIT_FSIZE, &small);
    std::string error;
    try {
        store.record(row);
    } catch (const std::exception& e) {
        error = e.what();
    }
    try {
        store.write_table();  // run 1 has no row: refused before writing
    } catch (const std::exception&) {
    }
    ::setrlimit(RLIMIT_FSIZE, &before);
    ::sigaction(SIGXFSZ, &previous, nullptr);
    EXPECT_NE(error.find("000000.json"), std::string::npos) << error;
    EXPECT_NE(error.find(std::strerror(EFBIG)), std::string::npos) << error;
    EXPECT_EQ(temporaries(out.path()), std::vector<std::string>{});
    EXPECT_FALSE(std::filesystem::exists(out.path() / "s" / "runs" / "000000.json"));
}

// What a sweep killed mid-write left (temporary files) is removed by --resume and by
// `fretbuzz clean`.
TEST(SweepStore, ResumeAndCleanRemoveWhatAStoppedSweepLeft) {
    SweepFixture f;
    const SweepSpec spec = f.spec("[[parameter]]\nkey = \"contact.K\"\nvalues = [1e9, 1e10]\n");
    const ScratchDir out("sweep-stale");
    const auto dir = out.path() / "s";
    run_sweep(spec, dir);
    const auto leave_stale = [&] {
        write_text(dir / "runs" / "000001.json.tmp-4242-1", "{\"index\": 1, \"valu");
        write_text(dir / "results.csv.tmp-4242-2", "run,contact");
        write_text(dir / "results.h5.tmp-4242", "");
    };
    leave_stale();
    SweepOptions resume;
    resume.resume = true;
    run_sweep(spec, dir, resume);
    EXPECT_EQ(temporaries(out.path()), std::vector<std::string>{});
    leave_stale();
    const auto cleaned = testing::run_cli("clean " + dir.string());
    EXPECT_EQ(cleaned.exit_code, 0) << cleaned.output;
    EXPECT_NE(cleaned.output.find("removed 3 temporary files"), std::string::npos) << cleaned.output;
    EXPECT_EQ(temporaries(out.path()), std::vector<std::string>{});
    EXPECT_TRUE(std::filesystem::exists(dir / "runs" / "000001.json"));
}

// One process at a time writes a sweep's folder: a second store (another `sweep --resume`)
// is refused while the first holds it, and `clean` leaves a running sweep alone.
TEST(SweepStore, ASecondSweepIntoTheSameFolderIsRefusedWhileTheFirstRuns) {
    SweepFixture f;
    const SweepSpec spec = f.spec("[[parameter]]\nkey = \"contact.K\"\nvalues = [1e9, 1e10]\n");
    const ScratchDir out("sweep-lock");
    const auto dir = out.path() / "s";
    {
        const SweepStore first(spec, dir, true);
        try {
            const SweepStore second(spec, dir, true);
            ADD_FAILURE() << "two stores write one folder";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find("another fretbuzz sweep is writing"), std::string::npos) << e.what();
        }
        const auto cli = testing::run_cli("sweep " + (f.dir.path() / "spec.toml").string() + " --resume --quiet --out " +
                                          dir.string());
        EXPECT_EQ(cli.exit_code, 2) << cli.output;
        EXPECT_NE(cli.output.find("another fretbuzz sweep is writing"), std::string::npos) << cli.output;
        EXPECT_EQ(testing::run_cli("clean " + dir.string()).exit_code, 2);
    }
    SweepOptions resume;
    resume.resume = true;
    EXPECT_EQ(run_sweep(spec, dir, resume).computed, 2u);  // the lock went with the first store
}

// `fretbuzz plot` (and report) on a sweep's folder: a clear refusal (exit 2) saying what the
// folder holds, not a traceback from the plotting script reading the table as a run.
TEST(SweepCommand, PlotOnASweepFolderSaysWhatItHolds) {
    SweepFixture f;
    const SweepSpec spec = f.spec("[[parameter]]\nkey = \"contact.K\"\nvalues = [1e9]\n");
    const ScratchDir out("sweep-plot");
    run_sweep(spec, out.path() / "s");
    for (const char* command : {"plot ", "report "}) {
        const auto r = testing::run_cli(command + (out.path() / "s").string());
        EXPECT_EQ(r.exit_code, 2) << r.output;
        EXPECT_NE(r.output.find("holds a sweep"), std::string::npos) << r.output;
        EXPECT_NE(r.output.find("fretbuzz.read_table"), std::string::npos) << r.output;
        EXPECT_EQ(r.output.find("Traceback"), std::string::npos) << r.output;
    }
}

// Ctrl-C (SIGINT) stops `fretbuzz sweep` with exit 130, the finished rows kept and the
// command that finishes the sweep printed; --resume then completes it.
TEST(SweepCommand, CtrlCExits130AndSaysHowToResume) {
    SweepFixture f;
    f.spec("[set]\nrun.duration = 0.05\n[[parameter]]\nkey = \"contact.K\"\nfrom = 1e8\nto = 1e10\ncount = 200\n");
    const ScratchDir out("sweep-sigint");
    const auto dir = out.path() / "s";
    const std::string log = (out.path() / "log.txt").string();
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 2, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    std::vector<std::string> words{FRETBUZZ_CLI, "sweep", (f.dir.path() / "spec.toml").string(), "--jobs", "1",
                                   "--out", dir.string()};
    std::vector<char*> argv;
    for (std::string& w : words) argv.push_back(w.data());
    argv.push_back(nullptr);
    pid_t pid = 0;
    ASSERT_EQ(posix_spawn(&pid, FRETBUZZ_CLI, &actions, nullptr, argv.data(), ::environ), 0);
    posix_spawn_file_actions_destroy(&actions);
    const auto rows = [&] {
        std::error_code ec;
        std::size_t n = 0;
        for (const auto& e : std::filesystem::directory_iterator(dir / "runs", ec))
            n += e.path().extension() == ".json" ? 1 : 0;
        return n;
    };
    for (int k = 0; k < 600 && rows() < 2; ++k) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    ::kill(pid, SIGINT);
    int status = 0;
    ::waitpid(pid, &status, 0);
    const std::string said = read_text(log);
    ASSERT_TRUE(WIFEXITED(status)) << said;
    EXPECT_EQ(WEXITSTATUS(status), 130) << said;
    EXPECT_NE(said.find("interrupted"), std::string::npos) << said;
    EXPECT_NE(said.find("--out " + dir.string() + " --resume"), std::string::npos) << said;
    EXPECT_FALSE(std::filesystem::exists(dir / "results.csv"));
    const std::size_t kept = rows();
    EXPECT_GE(kept, 2u);
    EXPECT_LT(kept, 200u);
    // Every row kept is a finished run (none recorded as failed by the interruption).
    const SweepSpec spec = load_sweep(f.dir.path() / "spec.toml");
    for (const SweepRow& row : SweepStore(spec, dir, true).rows_present()) EXPECT_TRUE(row.ok) << row.error;
}

}  // namespace
}  // namespace fretbuzz
