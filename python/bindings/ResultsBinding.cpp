// fretbuzz._core.RecordedRun: a finished run. Its arrays are read-only NumPy views of the
// recorded data (no copies), kept alive by the object they come from. fretbuzz.Results
// (python/fretbuzz/results.py) wraps it and takes every array property defined here.
#include <pybind11/numpy.h>

#include <string>
#include <vector>

#include "Bindings.hpp"
#include "fretbuzz/output/SummaryWriter.hpp"
#include "fretbuzz/run/ResultRecorder.hpp"

namespace fretbuzz::python {

namespace py = pybind11;

namespace {

py::array read_only_view(const py::object& owner, const std::vector<double>& data, std::vector<py::ssize_t> shape) {
    py::array_t<double> view(std::move(shape), data.data(), owner);
    view.attr("setflags")(py::arg("write") = false);
    return view;
}

using Member = std::vector<double> RecordedRun::*;

// A 1-D array property.
void vector_property(py::class_<RecordedRun>& cls, const char* name, Member member, const char* doc) {
    cls.def_property_readonly(
        name,
        [member](const py::object& self) {
            const RecordedRun& r = self.cast<const RecordedRun&>();
            return read_only_view(self, r.*member, {static_cast<py::ssize_t>((r.*member).size())});
        },
        doc);
}

// A 2-D array property, `columns` numbers per row.
void table_property(py::class_<RecordedRun>& cls, const char* name, Member member, std::size_t (RecordedRun::*columns)() const,
                    const char* doc) {
    cls.def_property_readonly(
        name,
        [member, columns](const py::object& self) {
            const RecordedRun& r = self.cast<const RecordedRun&>();
            const std::size_t width = (r.*columns)();
            const std::size_t rows = width == 0 ? 0 : (r.*member).size() / width;
            return read_only_view(self, r.*member, {static_cast<py::ssize_t>(rows), static_cast<py::ssize_t>(width)});
        },
        doc);
}

}  // namespace

void bind_results(py::module_& m) {
    py::class_<RecordedRun> cls(m, "RecordedRun", "The outputs of a run, as read-only NumPy arrays (SI units).");
    vector_property(cls, "time", &RecordedRun::time, "output times from t = 0 (s)");
    table_property(cls, "observation", &RecordedRun::observation, &RecordedRun::point_count,
                   "displacement u (m), samples x observation points");
    vector_property(cls, "points", &RecordedRun::observation_points_m, "observation points x (m)");
    vector_property(cls, "energy_time", &RecordedRun::energy_time, "times of the energy samples, (n - 1/2) dt (s)");
    vector_property(cls, "energy", &RecordedRun::energy, "discrete energy H^{n-1/2} (J)");
    vector_property(cls, "contact_energy", &RecordedRun::contact_energy, "contact part of the energy (J)");
    vector_property(cls, "dissipated", &RecordedRun::dissipated, "energy dissipated since the start (J)");
    // Two polarisations (empty with one): y and its energy terms.
    table_property(cls, "observation_y", &RecordedRun::observation_y, &RecordedRun::point_count,
                   "displacement along y (m), samples x observation points");
    vector_property(cls, "energy_y", &RecordedRun::energy_y, "energy of the y modes (J), part of energy");
    vector_property(cls, "damping_y", &RecordedRun::damping_y, "damping losses of the y modes so far (J)");
    vector_property(cls, "friction", &RecordedRun::friction, "friction dissipation so far (J)");
    vector_property(cls, "grid_x", &RecordedRun::grid_x, "interior grid points (m)");
    vector_property(cls, "obstacle_height", &RecordedRun::obstacle_height, "obstacle height at the grid points (m)");
    vector_property(cls, "first_contact", &RecordedRun::first_contact_s, "first contact time per grid point (s; NaN: never)");
    vector_property(cls, "last_contact", &RecordedRun::last_contact_s, "last contact time per grid point (s; NaN: never)");
    vector_property(cls, "peak_contact_force", &RecordedRun::peak_contact_force, "largest contact force per grid point (N/m)");
    vector_property(cls, "snapshot_time", &RecordedRun::snapshot_time, "times of the string snapshots (s)");
    table_property(cls, "snapshots", &RecordedRun::snapshots, &RecordedRun::grid_size,
                   "string shapes u (m), snapshots x grid points (empty unless run(..., snapshots=HZ))");
    cls.def_property_readonly(
        "summary",
        [](const RecordedRun& r) {
            return py::module_::import("json").attr("loads")(summary_json(r.summary, r.observation_points_m));
        },
        "the run summary (as in summary.json), a dict");
    cls.def("__repr__", [](const RecordedRun& r) {
        return "<fretbuzz.RecordedRun '" + r.summary.case_name + "': " + std::to_string(r.time.size()) + " samples x " +
               std::to_string(r.point_count()) + " points>";
    });
}

}  // namespace fretbuzz::python
