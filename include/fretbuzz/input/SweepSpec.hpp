#pragma once
// Sweep specs: one base case run over lists or grids of values of any case-file key (by
// its dotted path: contact.K, run.fs, string.T, obstacle.frets.height, ...). The spec and
// the base case are parsed once; each run's case is the base case's parsed document with
// the run's values set in it, read by the case-file reader, so a sweep checks its values
// exactly as a case file would and knows no schema of its own.
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
//
// The runs are counted before any is made: a grid of more than max_runs runs is refused
// (InputError naming the product of the list lengths), and a run's values are computed
// from its index when asked for, so a spec holds its lists, not its runs.
#include <cstddef>
#include <filesystem>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/input/CaseFile.hpp"

namespace fretbuzz {

// The most runs a spec may have unless told otherwise (fretbuzz sweep --max-runs, and
// fretbuzz.sweep(max_runs=...)).
inline constexpr std::size_t kDefaultMaxSweepRuns = 100000;
// The most that option may allow: row files are numbered with at most 9 digits.
inline constexpr std::size_t kMostSweepRuns = 999999999;

// One value of a swept key.
struct SweepValue {
    std::string key;     // dotted path
    std::string text;    // the value as it appears in the table (numbers: shortest exact form)
    bool label = false;  // a table column only: not written into the case
};

struct SweepRun {
    std::size_t index = 0;            // 0-based, in expansion order
    std::vector<SweepValue> values;   // one per parameter, in spec order
};

class SweepDocument;  // the parsed base case and the swept values, as parsed TOML

// A spec's runs, made from their index on demand (grid: the last parameter varies fastest).
class SweepRuns {
public:
    SweepRuns() = default;
    SweepRuns(std::shared_ptr<const SweepDocument> document, std::size_t count)
        : document_(std::move(document)), count_(count) {}
    std::size_t size() const { return count_; }
    bool empty() const { return count_ == 0; }
    SweepRun operator[](std::size_t index) const;  // InputError past the end

    class iterator {
    public:
        using iterator_category = std::input_iterator_tag;
        using value_type = SweepRun;
        using difference_type = std::ptrdiff_t;
        iterator(const SweepRuns* runs, std::size_t index) : runs_(runs), index_(index) {}
        SweepRun operator*() const { return (*runs_)[index_]; }
        iterator& operator++() {
            ++index_;
            return *this;
        }
        bool operator==(const iterator& other) const { return index_ == other.index_; }

    private:
        const SweepRuns* runs_;
        std::size_t index_;
    };
    iterator begin() const { return {this, 0}; }
    iterator end() const { return {this, count_}; }

    const SweepDocument& document() const { return *document_; }

private:
    std::shared_ptr<const SweepDocument> document_;
    std::size_t count_ = 0;
};

struct SweepSpec {
    std::string source_name;           // the spec file, for messages
    std::string text;                  // its TOML text (copied into the output directory)
    CaseText base;                     // the base case file
    std::vector<SweepValue> fixed;     // [set]
    std::vector<std::string> parameter_keys;
    SweepRuns runs;
    bool audio = false;
    double buzz_band_hz = 2000.0;
    std::size_t max_runs = kDefaultMaxSweepRuns;  // what it was read with
};

// Reads a spec; throws InputError naming the key at fault (unknown key, empty list,
// unknown case, more runs than max_runs). Does not check the values: see check_sweep.
SweepSpec parse_sweep(const std::string& text, const std::string& source_name, const std::filesystem::path& base_dir,
                      std::size_t max_runs = kDefaultMaxSweepRuns);
SweepSpec load_sweep(const std::filesystem::path& path, std::size_t max_runs = kDefaultMaxSweepRuns);

// The case of one run: the base case with [set] and the run's values set in its parsed
// document, read by the case-file reader. InputError names the run and the parameter.
Case sweep_case(const SweepSpec& spec, const SweepRun& run);
// The same with [obstacle] replaced by type = "none": nothing to touch.
Case sweep_case_without_obstacle(const SweepSpec& spec, const SweepRun& run);
// "run 3 (contact.K = 1e+13, run.fs = 400000)": a run in messages.
std::string describe(const SweepRun& run);

// The shortest %g form of a number that reads back as the same double ("400000", "1e+13").
std::string sweep_number_text(double value);

}  // namespace fretbuzz
