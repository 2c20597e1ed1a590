#pragma once
// What keeps a real-time voice safe, shared by Engine and BridgeEngine. The discrete energy is
// the guard: without input it can only decrease, so if H + dissipated - W ever exceeds the
// energy the events put in (each event's change of H + dissipated - W counted), the voice is
// silenced. And the block loop that steps M internal samples per host sample into the
// decimator, with subnormals flushed to zero while it runs.
#include <algorithm>
#include <cmath>
#include <span>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/SubnormalFlush.hpp"
#include "fretbuzz/realtime/Decimator.hpp"

namespace fretbuzz {

class EnergyGuard {
public:
    // Relative allowance: far above the round-off of the balance.
    static constexpr double kTolerance = 1e-6;
    // Below this fraction of the largest energy struck in, the voice is silent and not stepped.
    static constexpr double kSilentFraction = 1e-14;

    // From the ledger H + dissipated - W now: nothing injected yet beyond it.
    void start(double ledger) { injected_ = peak_ = ledger; }
    void restart(double ledger) { injected_ = ledger; }
    // Runs f, a change of state or plan, counting what it changes in the ledger as input.
    template <class Ledger, class Change>
    void change(const Ledger& ledger, Change&& f) {
        const double before = ledger();
        f();
        injected_ += ledger() - before;
    }
    void struck(double energy) { peak_ = std::max(peak_, energy); }
    // Whether the ledger is finite and within what was put in.
    bool holds(double ledger, double work) const {
        const double scale = std::max({std::abs(injected_), peak_, std::abs(work)});
        return std::isfinite(ledger) && ledger <= injected_ + kTolerance * scale;
    }
    bool sounding(double energy) const { return energy > kSilentFraction * peak_; }
    double injected() const { return injected_; }

private:
    double injected_ = 0.0;
    double peak_ = 0.0;  // largest energy after a strike: the scale of "silent"
};

// Renders out.size() host samples: `sample(decimator)` pushes the M internal samples of one
// host sample; the output is gain x the decimator's. While `sounding` is false nothing is
// stepped (the voice's time stands still) and the filter drains. False if a solve failed (the
// block is then zeros: the caller silences the voice).
template <class Sample>
bool render_block(std::span<float> out, Decimator& decimator, int factor, double gain, bool sounding, Sample&& sample) {
    const SubnormalFlush flushed;
    if (!sounding) {
        for (float& y : out) {
            for (int k = 0; k < factor; ++k) decimator.push(0.0);
            y = static_cast<float>(gain * decimator.output());
        }
        return true;
    }
    try {
        for (float& y : out) {
            sample(decimator);
            const double value = gain * decimator.output();
            y = std::isfinite(value) ? static_cast<float>(value) : 0.0f;
        }
    } catch (const SolverError&) {
        for (float& y : out) y = 0.0f;
        return false;
    }
    return true;
}

}  // namespace fretbuzz
