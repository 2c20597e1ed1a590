#pragma once
// The internal rate of a real-time voice: M times the host rate, M chosen so that every mode
// kept lies below kBandEdge x the internal rate (SamplingCheck's aliasing margin), and the
// case cut to those modes at that rate. Shared by the one-string Engine and the strings on a
// bridge (BridgeEngine), which choose M for their played string.
#include <cstddef>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/realtime/Engine.hpp"
#include "fretbuzz/scheme/Plan.hpp"

namespace fretbuzz {

// Modes are kept below this fraction of the internal rate: under the Nyquist frequency with
// a margin, so no mode aliases under contact (see SamplingCheck).
inline constexpr double kBandEdge = 0.45;

struct RateChoice {
    int factor;
    std::size_t modes;
    const char* reason;  // why M is what it is, as `play` prints it
};

// The number of c's first `available` modes below edge_hz.
std::size_t modes_below(const Case& c, std::size_t available, double edge_hz);
// M and the modes kept for c (see choose_rate in InternalRate.cpp for the figures behind it).
RateChoice choose_rate(const Case& c, const EngineOptions& o);
// InputError naming the first option out of its range.
void check_engine_options(const EngineOptions& o);
// c with its first `modes` modes (the open string cut, as StoppedString does at x = 0) and its
// sample rate set to internal_rate_hz. InputError if no mode is left.
Case case_at_internal_rate(const Case& c, std::size_t modes, int factor, double internal_rate_hz);
// The plan options of a voice of n modes: rows of S only where FFTW's transform would allocate.
PlanOptions realtime_plan_options(std::size_t n);

}  // namespace fretbuzz
