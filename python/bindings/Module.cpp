// fretbuzz._core, the compiled part of the `fretbuzz` Python package (python/fretbuzz/):
// load and edit cases, run them, get the results as NumPy arrays. Built with pybind11
// against the same library as the command line. Each binding file adds its part here.
#include <string>

#include "Bindings.hpp"
#include "fretbuzz/Version.hpp"

PYBIND11_MODULE(_core, m) {
    m.doc() = "Strings vibrating against obstacles (modal scheme with exact energy balance).\n\n"
              "    r = fretbuzz.run('bass-pop', fs=400000, duration=0.05)\n"
              "    r.time, r.observation, r.energy, r.dissipated, r.summary\n"
              "    c = fretbuzz.load_case('bass-pop'); c['K'] = 1e12; fretbuzz.run(c, fs=400000, duration=0.05)";
    m.attr("__version__") = std::string(fretbuzz::version);
    fretbuzz::python::bind_case(m);
    fretbuzz::python::bind_results(m);
    fretbuzz::python::bind_run(m);
    fretbuzz::python::bind_estimate(m);
    fretbuzz::python::bind_sweep(m);
    fretbuzz::python::bind_setup(m);
}
