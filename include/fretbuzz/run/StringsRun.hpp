#pragma once
// A run of strings on a bridge (StringsCase): every string planned once, stepped together in an
// Assembly; what it gives back is each string's energy over time (the energy passing between
// strings), the bridge's, the balance of the whole, the sound at the bridge and at each string's
// pickup. The rows and the sound go to an observer as the run makes them (the outputs write
// them to disk as they come, as a one-string run's writers do), or are kept (StringsRun).
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "fretbuzz/Case.hpp"

namespace fretbuzz {

// What the whole run tells, besides its rows.
struct StringsSummary {
    double output_rate_hz = 0.0;
    double audio_rate_hz = 0.0;
    long steps = 0;
    double wall_seconds = 0.0;
    // As a one-string run's (RunSummary), of the whole assembly, relative to the larger of the
    // energy after the first step and the largest |work| so far: the largest rise of H - W
    // between rows, and the largest |H + dissipated - W - H_first|.
    double max_relative_energy_increase = 0.0;
    double max_relative_balance_error = 0.0;
    // Coordinates of every string's and the bridge's modal state subnormal at the end: 0, since
    // the run flushes them (SubnormalFlush).
    std::size_t subnormal_coordinates = 0;
};

class StringsObserver {
public:
    virtual ~StringsObserver() = default;
    // One row, S + 3 numbers: t (s), each string's energy (J), the bridge's (J), the balance
    // ((H + dissipated - W - H_first) over the summary's scale).
    virtual void row(std::span<const double> values) = 0;
    // Frames at the audio rate, S + 1 numbers each: the bridge's speed (m/s), then each
    // string's displacement at its first observation point (m).
    virtual void audio(std::span<const double> frames) = 0;
};

// Rows of strings.csv per second when the case gives no output_rate.
inline constexpr double kStringsRowsPerSecond = 2000.0;

// Runs a validated case (StringsCase::validate, after any override); a signal stops it
// between blocks of steps (Interrupted).
StringsSummary simulate_strings(const StringsCase& sc, StringsObserver& observer);

// A run with its rows and sound kept in memory (short runs, tests).
struct StringsRun : StringsSummary {
    std::vector<double> t;                      // s, the rows of the energies
    std::vector<std::vector<double>> energy;    // J, string by string, at the rows
    std::vector<double> bridge_energy;          // J, at the rows
    std::vector<double> balance;                // at the rows
    std::vector<double> bridge_audio;               // the bridge's speed (m/s) at the audio rate
    std::vector<std::vector<double>> pickup_audio;  // each string's displacement at its first observation point (m)
};

StringsRun simulate_strings(const StringsCase& sc);

}  // namespace fretbuzz
