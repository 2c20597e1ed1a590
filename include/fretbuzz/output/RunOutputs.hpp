#pragma once
// The files of a run in one output directory: observation.csv, energy.csv,
// bridge_force.csv, the WAV files, results.h5 and summary.json. The command line and the Python module both write through
// this set, so they produce the same files. All-or-nothing: the files appear only on
// commit(); a run that throws (bad input, a failure, an interruption) leaves none.
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/output/AudioWriter.hpp"
#include "fretbuzz/run/RunObserver.hpp"

namespace fretbuzz {

struct RunOutputOptions {
    bool velocity_audio = false;  // also velocity.wav (what a magnetic pickup senses)
    double snapshot_rate_hz = 0.0;  // string shapes in results.h5; 0: none
    double snapshot_until_s = std::numeric_limits<double>::infinity();
    bool dense_contact_map = false;  // also the dense contact map in results.h5 (to check readers)
    std::string command_line{};  // how the run was asked for: recorded in summary.json and results.h5
    AudioFades fades{};          // of the WAV files
};

class RunOutputs {
public:
    // Creates the directory (throws InputError naming it if it cannot be written) and the
    // writers for case `c` (already validated).
    RunOutputs(const std::filesystem::path& dir, const Case& c, const RunOutputOptions& options = {});
    ~RunOutputs();
    RunOutputs(const RunOutputs&) = delete;
    RunOutputs& operator=(const RunOutputs&) = delete;

    // The writers, to pass to simulate() next to any other observers.
    const std::vector<RunObserver*>& observers() const { return observers_; }
    // After the run: moves the files into place.
    void commit();
    const std::filesystem::path& path() const;

private:
    struct Writers;
    std::unique_ptr<Writers> writers_;
    std::vector<RunObserver*> observers_;
};

}  // namespace fretbuzz
