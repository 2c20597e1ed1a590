// Sweeps: expansion of a spec into runs, values checked by the case-file parser, rows
// equal to single runs of the same parameters, resumption, and refusals of bad specs.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <filesystem>
#include <string>

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

}  // namespace
}  // namespace fretbuzz
