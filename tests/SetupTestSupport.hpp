#pragma once
// The instrument the set-up bench's unit tests play: the jazz bass simulated coarsely
// (500 kHz, a 2 mm grid, short notes, a few plucks a note). The directions the tests check
// are those of the geometry, far larger than what the coarse simulation changes.
#include <cstddef>

#include "fretbuzz/input/InstrumentFile.hpp"

namespace fretbuzz::testing {

inline Instrument quick_bass(std::size_t ensemble = 3, double duration_s = 0.1) {
    Instrument bass = load_instrument("jazz-bass");
    bass.bench.sample_rate_hz = 5e5;
    bass.bench.duration_s = duration_s;
    bass.bench.grid_step_m = 2e-3;
    bass.attack.ensemble = ensemble;
    return bass;
}

}  // namespace fretbuzz::testing
