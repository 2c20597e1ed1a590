#pragma once
// The instrument the set-up bench's unit tests play: the jazz bass simulated coarsely
// (500 kHz, a 2 mm grid, short notes, a few plucks a note). The directions the tests check
// are those of the geometry, far larger than what the coarse simulation changes.
#include <gtest/gtest.h>

#include <cstddef>
#include <string>

#include "fretbuzz/Error.hpp"
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

// The text with its first `from` replaced (a failure if there is none).
inline std::string replaced(std::string text, const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return text;
}

// An instrument file's text is refused with a message naming the key (and the range, if given).
inline void expect_instrument_refused(const std::string& text, const std::string& key, const std::string& range = "") {
    try {
        parse_instrument(text, "test.toml", DataSource::builtin());
        ADD_FAILURE() << "accepted: " << key;
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(key), std::string::npos) << what;
        if (!range.empty()) {
            EXPECT_NE(what.find(range), std::string::npos) << what;
        }
    }
}

}  // namespace fretbuzz::testing
