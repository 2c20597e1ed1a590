#pragma once
// Where a sweep keeps its results, so that an interrupted sweep loses nothing:
//   DIR/sweep.toml          the spec (a resumed sweep must have the same one)
//   DIR/sweep.lock          locked (flock) by the one process writing DIR: a second
//                           sweep into DIR is refused while the first runs
//   DIR/runs/NNNNNN.json    one row per finished run, written to a temporary file,
//                           flushed to disk and renamed: a row is there whole or not at all
//   DIR/runs/NNNNNN/        the run's audio, if asked for
//   DIR/results.csv, DIR/results.h5   the table of every row, rebuilt from the row files
#include <cstddef>
#include <filesystem>
#include <memory>
#include <vector>

#include "fretbuzz/sweep/Sweep.hpp"

namespace fretbuzz {

class SweepStore {
public:
    // A new sweep needs a directory that holds no other sweep (InputError naming --out);
    // with resume, DIR must hold this very spec (or nothing yet), and the temporary files
    // an earlier attempt left half-written are removed. InputError if another process
    // holds DIR's lock.
    SweepStore(const SweepSpec& spec, std::filesystem::path dir, bool resume);
    // Removes the temporary files (NAME.tmp-*) a stopped sweep left in DIR and DIR/runs;
    // returns how many. InputError if a sweep is writing DIR now.
    static std::size_t remove_stale_files(const std::filesystem::path& dir);

    // Runs without a row file, in index order.
    std::vector<std::size_t> missing() const;
    std::size_t present() const;
    std::filesystem::path audio_dir(std::size_t index) const;
    // Writes the row file atomically (safe from several threads: one file per row).
    void record(const SweepRow& row) const;
    // Every row, in index order (InputError naming a missing or unreadable row file).
    std::vector<SweepRow> rows() const;
    // The rows written so far, in index order.
    std::vector<SweepRow> rows_present() const;
    // results.csv and results.h5 from the row files, each replaced atomically.
    void write_table() const;
    const std::filesystem::path& dir() const { return dir_; }

private:
    struct Lock;
    static std::shared_ptr<Lock> lock(const std::filesystem::path& dir);
    std::filesystem::path row_path(std::size_t index) const;
    const SweepSpec& spec_;
    std::filesystem::path dir_;
    std::shared_ptr<Lock> lock_;
};

// The table as CSV text: run, the parameters, status, error, features, the metrics.
std::string sweep_table_csv(const SweepSpec& spec, const std::vector<SweepRow>& rows);

}  // namespace fretbuzz
