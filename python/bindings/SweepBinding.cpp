// Sweeps from Python: the spec (picklable, so Dask can ship it to workers), one run into
// one row, the store of row files and tables, and the local thread pool. The Python
// package (python/fretbuzz/sweeps.py) drives these: fretbuzz.sweep() locally or on a Dask
// cluster, `python3 -m fretbuzz.sweeps` for `fretbuzz sweep --scheduler`.
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <filesystem>
#include <memory>
#include <string>

#include "BackgroundRun.hpp"
#include "Bindings.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/sweep/Sweep.hpp"
#include "fretbuzz/sweep/SweepStore.hpp"

namespace fretbuzz::python {

namespace py = pybind11;

namespace {

// A spec with what is needed to read it again elsewhere (a Dask worker): its text, its
// name and the folder its relative case path is read from.
struct PySweepSpec {
    SweepSpec spec;
    std::string base_dir;
};

PySweepSpec parse_spec(const std::string& text, const std::string& source_name, const std::string& base_dir,
                       std::size_t max_runs) {
    return {parse_sweep(text, source_name, base_dir, max_runs), base_dir};
}

PySweepSpec load_spec(const std::string& path, std::size_t max_runs) {
    return {load_sweep(path, max_runs), std::filesystem::path(path).parent_path().string()};
}

// A store and the spec it refers to, kept alive together.
struct PySweepStore {
    std::shared_ptr<PySweepSpec> spec;
    SweepStore store;
};

py::dict outcome_dict(const SweepOutcome& o) {
    py::dict d;
    d["total"] = o.total;
    d["computed"] = o.computed;
    d["resumed"] = o.resumed;
    d["failed"] = o.failed;
    d["wall_seconds"] = o.wall_seconds;
    d["jobs"] = o.jobs;
    d["interrupted"] = o.interrupted;
    return d;
}

// run_sweep in the background (BackgroundRun): `progress` gets each report on this thread.
// Ctrl-C stops the sweep after the runs under way (their rows are kept) and raises
// KeyboardInterrupt.
py::dict run_local(const std::shared_ptr<PySweepSpec>& spec, const std::string& out, unsigned jobs, bool resume,
                   const py::object& progress) {
    BackgroundRun<SweepProgress> background;
    SweepOutcome outcome;
    SweepOptions options;
    options.jobs = jobs;
    options.resume = resume;
    options.stop = [&background] { return background.stopping(); };
    options.progress = [&](const SweepProgress& p) { background.post(p); };
    background.run([&] { outcome = run_sweep(spec->spec, out, options); },
                   [&](const SweepProgress& p) {
                       if (!progress.is_none()) progress(p);
                   });
    return outcome_dict(outcome);
}

}  // namespace

void bind_sweep(py::module_& m) {
    py::class_<SweepProgress>(m, "SweepProgress", "How far a sweep has gone, as passed to sweep(..., progress=callback).")
        .def_readonly("done", &SweepProgress::done, "runs in the table so far (resumed ones included)")
        .def_readonly("total", &SweepProgress::total, "runs in the sweep")
        .def_readonly("failed", &SweepProgress::failed, "failed runs so far")
        .def_readonly("resumed", &SweepProgress::resumed, "runs found from an earlier attempt")
        .def_readonly("elapsed_s", &SweepProgress::elapsed_s, "wall time of this attempt (s)")
        .def_readonly("remaining_s", &SweepProgress::remaining_s, "estimated wall time left (s)")
        .def(py::init([](std::size_t done, std::size_t total, std::size_t failed, std::size_t resumed, double elapsed,
                         double remaining) {
                 return SweepProgress{done, total, failed, resumed, elapsed, remaining};
             }),
             py::arg("done"), py::arg("total"), py::arg("failed"), py::arg("resumed"), py::arg("elapsed_s"),
             py::arg("remaining_s"))
        .def("__repr__", [](const SweepProgress& p) {
            return "<fretbuzz.SweepProgress " + std::to_string(p.done) + "/" + std::to_string(p.total) + ", " +
                   std::to_string(p.failed) + " failed>";
        });

    py::class_<PySweepSpec, std::shared_ptr<PySweepSpec>>(m, "SweepSpec",
                                                          "A sweep spec: a case and the values to run it over.")
        .def_static("load", &load_spec, py::arg("path"), py::arg("max_runs") = kDefaultMaxSweepRuns,
                    "Reads a spec file (.toml); InputError names a bad key, or the lists' lengths when they make\n"
                    "more than max_runs runs.")
        .def_static("parse", &parse_spec, py::arg("text"), py::arg("source_name") = "sweep spec",
                    py::arg("base_dir") = ".", py::arg("max_runs") = kDefaultMaxSweepRuns,
                    "A spec from its TOML text; a relative case path is read from base_dir.")
        .def_property_readonly("max_runs", [](const PySweepSpec& s) { return s.spec.max_runs; })
        .def_property_readonly("text", [](const PySweepSpec& s) { return s.spec.text; })
        .def_property_readonly("source_name", [](const PySweepSpec& s) { return s.spec.source_name; })
        .def_property_readonly("parameter_keys", [](const PySweepSpec& s) { return s.spec.parameter_keys; })
        .def_property_readonly("audio", [](const PySweepSpec& s) { return s.spec.audio; })
        .def("__len__", [](const PySweepSpec& s) { return s.spec.runs.size(); })
        .def(
            "check",
            [](const PySweepSpec& s, const py::object& progress) {
                SweepCheckProgress report;
                if (!progress.is_none()) {
                    // At most twice a second (and at the end), with the interpreter's lock.
                    auto last = std::make_shared<std::chrono::steady_clock::time_point>();
                    report = [&progress, last](std::size_t checked, std::size_t total) {
                        const auto now = std::chrono::steady_clock::now();
                        if (checked < total && now - *last < std::chrono::milliseconds(500)) return;
                        *last = now;
                        py::gil_scoped_acquire locked;
                        progress(checked, total);
                    };
                }
                py::gil_scoped_release unlocked;
                check_sweep(s.spec, report);
            },
            py::arg("progress") = py::none(),
            "Builds every run's case: InputError names the first bad value. progress(checked, total), if\n"
            "given, is called about twice a second.")
        .def(
            "case",
            [](const PySweepSpec& s, std::size_t index) { return sweep_case(s.spec, s.spec.runs[index]); },
            py::arg("index"), "The Case of one run: the base case with its values written in.")
        .def(
            "run_row",
            [](const PySweepSpec& s, std::size_t index, const std::string& audio_dir) {
                return without_gil([&] { return row_to_json(run_sweep_point(s.spec, index, audio_dir)); });
            },
            py::arg("index"), py::arg("audio_dir") = "",
            "Runs one run (and its obstacle-free reference); its row as one line of JSON.")
        .def(py::pickle(
            [](const PySweepSpec& s) {
                return py::make_tuple(s.spec.text, s.spec.source_name, s.base_dir, s.spec.max_runs);
            },
            [](const py::tuple& t) {
                return std::make_shared<PySweepSpec>(parse_spec(t[0].cast<std::string>(), t[1].cast<std::string>(),
                                                                t[2].cast<std::string>(), t[3].cast<std::size_t>()));
            }));

    py::class_<PySweepStore>(m, "SweepStore",
                             "The row files and tables of a sweep in a directory (see `fretbuzz sweep`).")
        .def(py::init([](std::shared_ptr<PySweepSpec> spec, const std::string& dir, bool resume) {
                 const SweepSpec& s = spec->spec;
                 return new PySweepStore{spec, SweepStore(s, dir, resume)};
             }),
             py::arg("spec"), py::arg("dir"), py::arg("resume") = false)
        .def("missing", [](const PySweepStore& s) { return s.store.missing(); }, "Runs without a row file, in order.")
        .def("audio_dir", [](const PySweepStore& s, std::size_t index) { return s.store.audio_dir(index).string(); })
        .def(
            "record", [](const PySweepStore& s, const std::string& row) { s.store.record(row_from_json(row)); },
            py::arg("row_json"), "Writes a row (as run_row returns it) to its file, atomically.")
        .def("failed", [](const PySweepStore& s) {
            std::size_t failed = 0;
            for (const SweepRow& row : s.store.rows_present()) failed += row.ok ? 0 : 1;
            return failed;
        })
        .def("write_table", [](const PySweepStore& s) { s.store.write_table(); },
             "results.csv and results.h5 from the row files (InputError if some are missing).");

    m.def("sweep_metric_names", &sweep_metric_names, "The metric columns of a sweep table, in order.");
    m.def("run_sweep_local", &run_local, py::arg("spec"), py::arg("out"), py::arg("jobs") = 0,
          py::arg("resume") = false, py::arg("progress") = py::none(),
          "The compiled local sweep behind fretbuzz.sweep(); see there.");
}

}  // namespace fretbuzz::python
