#pragma once
// Parameter sweeps: one base case run over lists or grids of values of any case-file key
// (by its dotted path: contact.K, run.fs, string.T, obstacle.frets.height, ...). Each
// value is written into the case file's TOML document, which is then read again by the
// case-file parser, so a sweep checks its values exactly as a case file would and knows
// no schema of its own. Each run gives one row of a table (parameters, status, buzz
// metrics); failed runs stay in it with their error.
//
// A spec file:
//   [sweep]
//   case = "bass-pop"        # built-in name or .toml path (relative to the spec)
//   combine = "grid"         # "grid": every combination; "zip": the k-th values together
//   audio = false            # keep each run's audio.wav under runs/
//   buzz_band = 2000         # Hz: the buzz measure's lower band edge
//   [set]                    # the same value in every run
//   "run.duration" = 0.5
//   [[parameter]]
//   key = "contact.K"
//   values = [1e12, 1e13]    # or: from = 1e12, to = 1e14, count = 3, scale = "log"
//   [[parameter]]
//   key = "fret"             # label = true: a column of the table only, not a case key
//   label = true             # (tags runs, e.g. the note each run stands for)
//   values = [0, 1]
#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/input/CaseFile.hpp"

namespace fretbuzz {

// One value of a swept key: a TOML value written as TOML text ("1e13", "\"table\"").
struct SweepValue {
    std::string key;   // dotted path
    std::string toml;  // the value as TOML text
    std::string text;  // the value as it appears in the table (numbers: shortest exact form)
    bool label = false;  // a table column only: not written into the case
};

struct SweepRun {
    std::size_t index = 0;            // 0-based, in expansion order
    std::vector<SweepValue> values;   // one per parameter, in spec order
};

struct SweepSpec {
    std::string source_name;           // the spec file, for messages
    std::string text;                  // its TOML text (copied into the output directory)
    CaseText base;                     // the base case file
    std::vector<SweepValue> fixed;     // [set]
    std::vector<std::string> parameter_keys;
    std::vector<SweepRun> runs;
    bool audio = false;
    double buzz_band_hz = 2000.0;
};

// Reads a spec; throws InputError naming the key at fault (unknown key, empty list,
// unknown case). Does not check the values: see check_sweep.
SweepSpec parse_sweep(const std::string& text, const std::string& source_name,
                      const std::filesystem::path& base_dir);
SweepSpec load_sweep(const std::filesystem::path& path);

// The case of one run: the base case file with [set] and the run's values written in,
// read by the case-file parser. InputError names the run and the parameter.
Case sweep_case(const SweepSpec& spec, const SweepRun& run);
// The same case with its obstacle removed ([obstacle] type = "none"): the buzz reference.
// A case with fingers keeps its obstacle up to the stopping fret (see first_buzz_point).
Case obstacle_free_case(const SweepSpec& spec, const SweepRun& run);
// Builds every run's case once, so a bad value stops the sweep before anything runs.
void check_sweep(const SweepSpec& spec);

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

// The shortest %g form of a number that reads back as the same double ("400000", "1e+13").
std::string sweep_number_text(double value);

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
};

struct SweepOutcome {
    std::size_t total = 0, computed = 0, resumed = 0, failed = 0;
    double wall_seconds = 0.0;
    unsigned jobs = 1;
    bool interrupted = false;   // stopped early: rows kept, no table (finish with resume)
};

// Runs the missing rows of a sweep into `out` (see SweepStore) and writes the table.
SweepOutcome run_sweep(const SweepSpec& spec, const std::filesystem::path& out, const SweepOptions& options = {});

}  // namespace fretbuzz
