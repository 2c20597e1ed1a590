#include "fretbuzz/run/Simulation.hpp"

#include <algorithm>
#include <cmath>

#include "ImpactRun.hpp"
#include "RunLoop.hpp"

namespace fretbuzz {

long output_stride(const Case& c) {
    if (!c.run.output_rate_hz) return 1;
    return std::max(1L, std::lround(c.run.sample_rate_hz / *c.run.output_rate_hz));
}

RunSummary simulate(const Case& c, std::span<RunObserver* const> observers, const RunOptions& options) {
    c.validate();
    // The law is chosen once, here: the penalty's run loop or the impact law's.
    if (c.contact.law == ContactLawKind::impact) return run_impact(c, observers, options);
    return RunLoop(c, observers, options).run();
}

}  // namespace fretbuzz
