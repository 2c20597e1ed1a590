// fretbuzz.run: simulate a case (a name, a .toml path or a Case) with optional overrides,
// the interpreter lock released while the scheme runs.
#include <pybind11/stl.h>

#include <optional>
#include <string>
#include <vector>

#include "Bindings.hpp"
#include "Conversions.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/io/CaseFile.hpp"
#include "fretbuzz/run/ResultRecorder.hpp"
#include "fretbuzz/run/Simulation.hpp"

namespace fretbuzz::python {

namespace py = pybind11;

namespace {

Case case_from(const py::handle& source) {
    if (py::isinstance<Case>(source)) return source.cast<Case>();  // a copy: the caller's case is left as it is
    if (py::isinstance<py::str>(source) || py::hasattr(source, "__fspath__"))
        return load_case(py::str(py::module_::import("os").attr("fspath")(source)).cast<std::string>());
    throw py::type_error("case: expected a built-in case name, a path to a .toml file or a fretbuzz.Case");
}

void set_output_rate(Case& c, const py::handle& rate) {
    if (rate.is_none()) return;
    if (py::isinstance<py::str>(rate)) {
        if (rate.cast<std::string>() != "native") throw InputError("output_rate: must be a rate in Hz or 'native'");
        c.run.output_rate_hz.reset();
    } else {
        c.run.output_rate_hz = rate.cast<double>();
    }
}

RecordedRun run(const py::handle& source, std::optional<double> fs, std::optional<double> duration,
                const py::handle& observe, const py::handle& output_rate, bool lossless, std::optional<double> stiffness,
                std::optional<double> exponent, double snapshots, bool screen) {
    Case c = case_from(source);
    if (fs) c.run.sample_rate_hz = *fs;
    if (duration) c.run.duration_s = *duration;
    if (stiffness) c.contact.stiffness = *stiffness;
    if (exponent) c.contact.exponent = *exponent;
    if (lossless) c.make_lossless();
    if (!observe.is_none()) c.observation_points_m = to_vector(observe, "observe");
    set_output_rate(c, output_rate);
    c.validate();
    if (!(snapshots >= 0.0 && snapshots <= c.run.sample_rate_hz))
        throw InputError(out_of_range_message("snapshots (Hz)", snapshots, "must be in [0, fs] (0 for none)"));

    ResultRecorder recorder(snapshots);
    RunObserver* observers[] = {&recorder};
    RunOptions options;
    options.plan.screen_contacts = screen;
    {
        py::gil_scoped_release unlocked;
        simulate(c, observers, options);
    }
    return recorder.take();
}

}  // namespace

void bind_run(py::module_& m) {
    m.def("run", &run, py::arg("case"), py::kw_only(), py::arg("fs") = py::none(), py::arg("duration") = py::none(),
          py::arg("observe") = py::none(), py::arg("output_rate") = py::none(), py::arg("lossless") = false,
          py::arg("K") = py::none(), py::arg("alpha") = py::none(), py::arg("snapshots") = 0.0,
          py::arg("screen") = true,
          "Runs a case and returns its Results.\n\n"
          "case: built-in name, path to a .toml file, or a Case (not modified).\n"
          "fs, duration, K, alpha: override the case's values. observe: replace the observation points (m).\n"
          "output_rate: rows per second, or 'native' for every step. lossless: remove all damping.\n"
          "snapshots: also record the string shape at this rate (Hz). screen: skip points that cannot touch.");
}

}  // namespace fretbuzz::python
