// The held-string stand-in against the pinned one on the single-string bass: the held string
// sounds a few cents higher (it is partly clamped over the fret), and the finger's loss damps
// its upper partials several times faster than the string's own (scheme/HeldString.hpp), so
// its buzz map may differ from the pinned string's: where a pitch change of that size changes
// the pinned map itself, or lower (more loss only calms a note). The pinned string retuned by
// 0 to +5 cents spans what pitch alone does to each note's verdict; the held string's verdict
// must not lie above that span (one pluck of slack, the ensemble's resolution).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <utility>

#include "fretbuzz/input/InstrumentFile.hpp"
#include "fretbuzz/setup/Attack.hpp"
#include "fretbuzz/setup/BuzzMap.hpp"

namespace fretbuzz {
namespace {

Instrument coarse_bass_neck(bool pinned, double cents) {
    Instrument bass = load_instrument("bass-neck");
    bass.bench.sample_rate_hz = 5e5;
    bass.bench.duration_s = 0.08;
    bass.bench.grid_step_m = 2e-3;
    bass.attack.ensemble = 5;
    bass.bench.pinned_stops = pinned;
    // A pitch change at the same linear density: f scales by 2^(c/1200), the tension by its square.
    const double ratio = std::exp2(cents / 1200.0);
    for (InstrumentString& s : bass.strings) {
        s.frequency_hz *= ratio;
        s.tension_n *= ratio * ratio;
    }
    return bass;
}

std::map<std::pair<std::size_t, std::string>, NoteVerdict> map_of(const Instrument& bass) {
    MapRequest request;
    request.attacks = parse_attacks("0.9mm,1mm,1.2mm", bass.attack);
    request.jobs = 2;
    std::map<std::pair<std::size_t, std::string>, NoteVerdict> notes;
    for (NoteVerdict& v : play_map(bass, request).notes) notes[{v.fret, v.strength}] = std::move(v);
    return notes;
}

TEST(SetupHeldStops, TheHeldStandInNeverBuzzesMoreThanItsPitchExplains) {
    const auto held = map_of(coarse_bass_neck(false, 0.0));
    std::map<std::pair<std::size_t, std::string>, std::pair<double, double>> span;  // buzz fraction: lowest, highest
    for (const double cents : {0.0, 1.25, 2.5, 3.75, 5.0})
        for (const auto& [key, v] : map_of(coarse_bass_neck(true, cents))) {
            auto [it, added] = span.try_emplace(key, v.buzz_fraction, v.buzz_fraction);
            it->second.first = std::min(it->second.first, v.buzz_fraction);
            it->second.second = std::max(it->second.second, v.buzz_fraction);
        }
    ASSERT_EQ(held.size(), span.size());
    std::size_t differing = 0, calmer = 0;
    for (const auto& [key, v] : held) {
        ASSERT_EQ(v.status, "ok") << "fret " << key.first << " " << key.second;
        const auto [low, high] = span.at(key);
        const double slack = 1.0 / static_cast<double>(v.plucks) + 1e-9;
        if (v.buzz_fraction > high + 1e-9) ++differing;
        if (v.buzz_fraction < low - 1e-9) ++calmer;
        EXPECT_LE(v.buzz_fraction, high + slack) << "fret " << key.first << " " << key.second;
    }
    // The slack is for the odd note at the edge of chaos, not a general licence.
    EXPECT_LE(differing, held.size() / 10) << differing << " of " << held.size() << " verdicts above the pitch span";
    std::printf("%zu of %zu verdicts above the pitch span, %zu below it\n", differing, held.size(), calmer);
}

}  // namespace
}  // namespace fretbuzz
