#include "fretbuzz/realtime/InternalRate.hpp"

#include <algorithm>
#include <limits>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/StoppedString.hpp"

namespace fretbuzz {

namespace {
constexpr const char* kRateAsked = "set by the oversampling option";
constexpr const char* kRateEveryMode =
    "the smallest that keeps every mode below 0.45 x the internal rate (a lower one drops modes the contact needs)";
constexpr const char* kRateCapped =
    "capped by max_oversampling: the modes above 0.45 x the internal rate are dropped";
}  // namespace

std::size_t modes_below(const Case& c, std::size_t available, double edge_hz) {
    std::size_t n = 0;
    while (n < available && c.modes.frequency_hz[n] < edge_hz) ++n;
    return n;
}

// The default keeps every mode of the case: the contact needs them. Measured by
// fretbuzz_rate_accuracy (first 0.5 s after a strike, against the same voice at M = 8, which
// M = 16 confirms to 0.3 dB): a rate that drops modes changes the tanpura by 2.3 dB
// (log-spectral distance over 1/6-octave bands) and its centroid by 6 % at M = 2, 5.9 dB and
// 23 % at M = 4, the sitar by 3.2 dB / 6 % and 5.5 dB / 8 %; not monotonically in M (the
// point contact's stiffness depends on where the modal series is cut). With the same modes,
// M = 2 and M = 8 differ by 1.4 dB: the modes dropped, more than the step, are the error.
RateChoice choose_rate(const Case& c, const EngineOptions& o) {
    const std::size_t available = o.max_modes > 0 ? std::min(o.max_modes, c.mode_count()) : c.mode_count();
    const auto below = [&](int m) { return modes_below(c, available, kBandEdge * m * o.host_rate_hz); };
    if (o.oversampling > 0) return {o.oversampling, below(o.oversampling), kRateAsked};
    for (int m = 1; m <= o.max_oversampling; ++m)
        if (below(m) == available) return {m, available, kRateEveryMode};
    return {o.max_oversampling, below(o.max_oversampling), kRateCapped};
}

void check_engine_options(const EngineOptions& o) {
    const auto in = [](const char* name, double v, double low, double high, const char* range) {
        if (!(v >= low && v <= high)) throw InputError(out_of_range_message(name, v, range));
    };
    in("host rate (Hz)", o.host_rate_hz, 8000.0, 768000.0, "[8000, 768000]");
    in("oversampling", o.oversampling, 0, 64, "0 (automatic) to 64");
    in("max oversampling", o.max_oversampling, 1, 64, "1 to 64");
    in("taps per phase", o.taps_per_phase, 4, 256, "4 to 256");
    in("gain per metre", o.gain_per_m, 0.0, 1e9, "[0, 1e9]");
}

Case case_at_internal_rate(const Case& c, std::size_t modes, int factor, double internal_rate_hz) {
    if (modes == 0)
        throw InputError(out_of_range_message("oversampling", factor,
                                              "high enough that the first mode lies below 0.45 x the internal rate"));
    Case out = modes == c.mode_count() ? c : stopped_string(c, 0.0, modes);
    out.run.sample_rate_hz = internal_rate_hz;
    return out;
}

PlanOptions realtime_plan_options(std::size_t n) {
    PlanOptions options;
    if (sine_transform_allocates(n)) options.transform_threshold = std::numeric_limits<std::size_t>::max();
    return options;
}

}  // namespace fretbuzz
