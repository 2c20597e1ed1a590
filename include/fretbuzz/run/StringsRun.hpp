#pragma once
// A run of strings on a bridge (StringsCase): every string planned once, stepped together in an
// Assembly; what it gives back is each string's energy over time (the energy passing between
// strings), the bridge's, the balance of the whole, the sound at the bridge and at each string's
// pickup.
#include <cstddef>
#include <string>
#include <vector>

#include "fretbuzz/Case.hpp"

namespace fretbuzz {

struct StringsRun {
    double output_rate_hz = 0.0;
    std::vector<double> t;                      // s, the rows of the energies
    std::vector<std::vector<double>> energy;    // J, string by string, at the rows
    std::vector<double> bridge_energy;          // J, at the rows
    // (H + dissipated - work - H_first) / H_first at the rows: the whole assembly's balance.
    std::vector<double> balance;
    double audio_rate_hz = 0.0;
    std::vector<double> bridge_audio;               // the bridge's speed (m/s) at the audio rate
    std::vector<std::vector<double>> pickup_audio;  // each string's displacement at its first observation point (m)
    long steps = 0;
    double wall_seconds = 0.0;
    double worst_balance = 0.0;
    // Coordinates of every string's and the bridge's modal state subnormal at the end: 0, since
    // the run flushes them (SubnormalFlush).
    std::size_t subnormal_coordinates = 0;
};

// Rows of strings.csv per second when the case gives no output_rate.
inline constexpr double kStringsRowsPerSecond = 2000.0;

StringsRun simulate_strings(const StringsCase& sc);

}  // namespace fretbuzz
