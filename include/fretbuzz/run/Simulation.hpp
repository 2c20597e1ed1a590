#pragma once
// The driver: plans a Case, steps it to the end, and feeds the observers.
#include <functional>
#include <span>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/run/RunObserver.hpp"
#include "fretbuzz/scheme/Plan.hpp"

namespace fretbuzz {

struct Progress {
    double fraction;         // 0..1
    double simulated_s;
    double elapsed_s;
    double remaining_s;      // estimate
};

struct RunOptions {
    PlanOptions plan;
    // Jump over output intervals where no contact is possible (see Stepper::free_flight).
    bool free_flight = true;
    // During long flights, write the resampled audio in closed form rather than resampling the
    // per-step signal (see AudioBand); false: the per-step path throughout (the reference).
    bool closed_form_audio = true;
    // Make the audio (resampling, closed form, the observers' audio() calls) on a second thread
    // while the string steps (one polarisation); the same samples as made inline, bit for bit.
    bool per_step_thread = true;
    // Called about twice a second of wall time, if set.
    std::function<void(const Progress&)> progress;
};

// Output stride for a case: one row per step for "native", else round(fs / output_rate).
long output_stride(const Case& c);

RunSummary simulate(const Case& c, std::span<RunObserver* const> observers, const RunOptions& options = {});

}  // namespace fretbuzz
