#pragma once
// A case run for another duration than its file says (fretbuzz run --duration, Python's
// duration=): its time profiles follow the run.
#include "fretbuzz/Case.hpp"

namespace fretbuzz {

// Sets run.duration and cuts the fingers' and force gestures' profiles to the run: each
// keeps its points up to the first at or past the end (it fixes the force within the run;
// the rest would never act). A pluck or pop that would start after the end is left out,
// and c.warnings says so. A duration that is not a positive number is set as it is, for
// Case::validate to refuse.
void set_duration(Case& c, double duration_s);
// The same for strings on a bridge: the case's [run] and every string's (their profiles cut,
// their warnings in each string's Case). StringsCase::validate checks the result.
void set_duration(StringsCase& sc, double duration_s);

}  // namespace fretbuzz
