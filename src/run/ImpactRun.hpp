#pragma once
// The run of a case whose obstacle acts by Newton's impact law (scheme/NewtonImpact.hpp): the
// same observers and outputs as the penalty's run loop (observation and bridge-force rows and the
// audited energy at the output rate, the contacts of every step, the audio from the per-step
// signal, free flight over output intervals between contacts). Snapshots of the string's shape
// are refused (InputError).
#include <span>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/run/RunObserver.hpp"
#include "fretbuzz/run/Simulation.hpp"

namespace fretbuzz {

RunSummary run_impact(const Case& c, std::span<RunObserver* const> observers, const RunOptions& options);

}  // namespace fretbuzz
