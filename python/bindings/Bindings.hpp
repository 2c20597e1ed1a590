#pragma once
// The pieces of the `fretbuzz` Python module, each defined in its own file.
#include <pybind11/pybind11.h>

namespace fretbuzz::python {

void bind_case(pybind11::module_& m);     // Case, load_case, cases
void bind_results(pybind11::module_& m);  // RecordedRun (wrapped by fretbuzz.Results)
void bind_run(pybind11::module_& m);      // simulate, Progress
void bind_estimate(pybind11::module_& m);  // estimate
void bind_sweep(pybind11::module_& m);     // SweepSpec, SweepStore, run_sweep_local
void bind_setup(pybind11::module_& m);     // Instrument, load_instrument, the set-up bench

}  // namespace fretbuzz::python
