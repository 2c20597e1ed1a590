#pragma once
// Parameter sweeps: one base case run over lists or grids of values of any case-file key
// (the spec is read by the input floor: fretbuzz/input/SweepSpec.hpp). Each run gives one
// row of a table (parameters, status, buzz metrics); failed runs stay in it with their
// error. An interrupted sweep keeps its finished rows and resumes (see SweepStore).
#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/input/SweepSpec.hpp"

namespace fretbuzz {

// The same case with its obstacle removed ([obstacle] type = "none"): the buzz reference.
// A case with fingers keeps its obstacle up to the stopping fret (see first_buzz_point).
Case obstacle_free_case(const SweepSpec& spec, const SweepRun& run);

// How far check_sweep has gone: runs checked of the total.
using SweepCheckProgress = std::function<void(std::size_t checked, std::size_t total)>;
// Builds every run's case once, so a bad value stops the sweep before anything runs (the
// InputError of the lowest failing run). On `jobs` threads (0: the hardware's); `progress`
// (if set) hears about every run checked, one call at a time; a stop asked for (Ctrl-C)
// throws Interrupted.
void check_sweep(const SweepSpec& spec, const SweepCheckProgress& progress = {}, unsigned jobs = 0);

// One row of the result table.
struct SweepRow {
    std::size_t index = 0;
    std::vector<std::string> values;   // the run's parameter values (table text)
    bool ok = false;
    std::string error;                 // why it failed (empty when ok)
    std::string features;              // obstacle features touched, e.g. "3 4 5" (frets)
    std::vector<double> metrics;       // in sweep_metric_names() order; NaN where undefined
    double wall_seconds = 0.0;         // not in the table (tables of equal sweeps are equal)
};

// The metric columns, in table order.
const std::vector<std::string>& sweep_metric_names();

// Runs one run (and its obstacle-free reference) and returns its row; failures of the
// run itself become failed rows. `audio_dir`: where to put audio.wav (empty: none).
SweepRow run_sweep_point(const SweepSpec& spec, std::size_t index, const std::filesystem::path& audio_dir = {});

// Rows as one-line JSON (the row files under runs/, and what Dask workers return).
std::string row_to_json(const SweepRow& row);
SweepRow row_from_json(const std::string& json);

struct SweepProgress {
    std::size_t done = 0;       // rows in the table, resumed ones included
    std::size_t total = 0;
    std::size_t failed = 0;
    std::size_t resumed = 0;    // rows found from an earlier attempt
    double elapsed_s = 0.0;
    double remaining_s = 0.0;   // estimate from this attempt's rate
};

struct SweepOptions {
    unsigned jobs = 0;          // runs at a time; 0: the hardware's threads
    bool resume = false;
    std::function<void(const SweepProgress&)> progress;  // after every finished run
    std::function<bool()> stop;  // asked before each run starts: true ends the sweep early
    SweepCheckProgress checking;  // while every run's case is checked, before any runs
};

struct SweepOutcome {
    std::size_t total = 0, computed = 0, resumed = 0, failed = 0;
    double wall_seconds = 0.0;
    unsigned jobs = 1;
    bool interrupted = false;   // stopped early: rows kept, no table (finish with resume)
    int signal = 0;             // the signal that stopped it (SIGINT, SIGTERM), 0 if `stop` did
};

// Runs the missing rows of a sweep into `out` (see SweepStore) and writes the table.
SweepOutcome run_sweep(const SweepSpec& spec, const std::filesystem::path& out, const SweepOptions& options = {});

}  // namespace fretbuzz
