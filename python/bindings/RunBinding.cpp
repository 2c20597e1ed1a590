// fretbuzz._core.simulate: runs a validated Case, the interpreter lock released while the
// scheme runs. Optionally writes the command line's output files (through the library's
// RunOutputs, as `fretbuzz run --out` does) and reports progress. Ctrl-C is checked every
// 0.2 s: it raises KeyboardInterrupt, and an output directory then receives no files. The Python-level run() (python/fretbuzz/__init__.py)
// resolves names and overrides, then calls this.
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <optional>
#include <string>
#include <vector>

#include "BackgroundRun.hpp"
#include "Bindings.hpp"
#include "Conversions.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/output/AudioWriter.hpp"
#include "fretbuzz/output/RunOutputs.hpp"
#include "fretbuzz/run/ResultRecorder.hpp"
#include "fretbuzz/run/Simulation.hpp"

namespace fretbuzz::python {

namespace py = pybind11;

namespace {

// The Python program that asked for the run, for the outputs' provenance.
std::string python_command_line() {
    std::string line = "python";
    for (const py::handle arg : py::module_::import("sys").attr("argv")) {
        line.push_back(' ');
        line.append(py::str(arg).cast<std::string>());
    }
    line.append(" (fretbuzz.run)");
    return line;
}

// Memory the system can still give (Linux's MemAvailable), or 0 when unknown.
double available_memory_bytes() {
    std::ifstream meminfo("/proc/meminfo");
    std::string key;
    double kib = 0.0;
    std::string unit;
    while (meminfo >> key >> kib >> unit)
        if (key == "MemAvailable:") return kib * 1024.0;
    return 0.0;
}

// The run keeps every output row (and snapshot) in memory: refuse up front, naming the
// parameters, a run whose arrays would not fit, instead of a MemoryError naming nothing.
void require_memory_for(const Case& c, double snapshot_rate, double snapshot_until) {
    const double rate = c.run.output_rate_hz.value_or(c.run.sample_rate_hz);
    const double rows = c.run.duration_s * rate + 1.0;
    const double points = static_cast<double>(c.observation_points_m.size());
    // time and u per observation point; H, its contact part, the dissipated energy and
    // their times; with two polarisations y per point and three y energy terms.
    const double columns = 1.0 + points + 4.0 + (c.two_polarisations() ? points + 3.0 : 0.0);
    const double snapshots = snapshot_rate * std::min(c.run.duration_s, snapshot_until);
    const double bytes = 8.0 * (rows * columns + snapshots * (static_cast<double>(c.mode_count()) + 1.0));
    const double available = available_memory_bytes();
    if (available <= 0.0 || bytes <= 0.8 * available) return;
    const auto g = [](double x, int digits) {
        std::ostringstream text;
        text.precision(digits);
        text << x;
        return text.str();
    };
    std::ostringstream why;
    why << "duration = " << g(c.run.duration_s, 12) << " s at output_rate = "
        << (c.run.output_rate_hz ? g(*c.run.output_rate_hz, 12) + " Hz"
                                 : "native (every step of fs = " + g(c.run.sample_rate_hz, 12) + " Hz)");
    if (snapshot_rate > 0.0) why << " with snapshots = " << g(snapshot_rate, 12) << " Hz";
    why << ": the results kept in memory would take " << g(bytes / 1e9, 3) << " GB, more than the "
        << g(available / 1e9, 3) << " GB this machine has available; shorten duration, lower output_rate (e.g. 48000)"
        << (snapshot_rate > 0.0 ? ", lower snapshots or set snapshot_until" : "")
        << ", or run it with `fretbuzz run`, which streams its outputs to files";
    throw InputError(why.str());
}

// The WAV fades: None keeps the writers' defaults.
AudioFades fades_of(const py::object& fade_in, const py::object& fade_out) {
    AudioFades fades;
    if (!fade_in.is_none()) fades.in_s = to_number(fade_in, "fade_in");
    if (!fade_out.is_none()) fades.out_s = to_number(fade_out, "fade_out");
    require_non_negative("fade_in (s)", fades.in_s);
    require_non_negative("fade_out (s)", fades.out_s);
    return fades;
}

RecordedRun simulate_case(const Case& c, const py::object& snapshots, bool screen, bool free_flight, const py::object& out,
                          bool velocity_audio, const py::object& snapshot_until, const py::object& progress,
                          const py::object& fade_in, const py::object& fade_out) {
    c.validate();
    const AudioFades fades = fades_of(fade_in, fade_out);
    const double snapshot_rate = to_number(snapshots, "snapshots");
    if (!(snapshot_rate >= 0.0 && snapshot_rate <= c.run.sample_rate_hz))
        throw InputError(out_of_range_message("snapshots (Hz)", snapshot_rate, "must be in [0, fs] (0 for none)"));
    const double until =
        snapshot_until.is_none() ? std::numeric_limits<double>::infinity() : to_number(snapshot_until, "snapshot_until");
    if (!snapshot_until.is_none()) require_positive("snapshot_until (s)", until);
    if (!progress.is_none() && !PyCallable_Check(progress.ptr()))
        throw py::type_error("progress: expected a callable taking a fretbuzz.Progress, got " + type_name(progress));
    require_memory_for(c, snapshot_rate, until);

    std::optional<RunOutputs> outputs;
    if (!out.is_none())
        outputs.emplace(py::str(py::module_::import("os").attr("fspath")(out)).cast<std::string>(), c,
                        RunOutputOptions{.velocity_audio = velocity_audio,
                                         .snapshot_rate_hz = snapshot_rate,
                                         .snapshot_until_s = until,
                                         .command_line = python_command_line(),
                                         .fades = fades});
    ResultRecorder recorder(snapshot_rate);
    std::vector<RunObserver*> observers{&recorder};
    if (outputs) observers.insert(observers.end(), outputs->observers().begin(), outputs->observers().end());

    RunOptions options;
    options.plan.screen_contacts = screen;
    options.free_flight = free_flight;
    // On a thread of its own (BackgroundRun): this one looks for Ctrl-C every 0.2 s and calls
    // `progress` with each report; a Python exception (KeyboardInterrupt, or one the callback
    // raises) stops the run at its next report, and a daemon thread at the interpreter's end
    // stops it and ends without aborting the process.
    BackgroundRun<Progress> background;
    options.progress = [&background](const Progress& p) {
        if (background.stopping()) throw Interrupted(SIGINT);
        background.post(p);
    };
    RunSummary summary;
    background.run([&] { summary = simulate(c, observers, options); },
                   [&progress](const Progress& p) {
                       if (!progress.is_none()) progress(p);
                   });
    // Every run reports its end, however short: the callback sees 100 %, and what it raises
    // then reaches the caller as it would have mid-run (and `out` receives no files).
    if (!progress.is_none())
        progress(Progress{1.0, summary.duration_s, summary.wall_seconds, 0.0});
    if (outputs) outputs->commit();
    return recorder.take();
}

}  // namespace

void bind_run(py::module_& m) {
    py::class_<Progress>(m, "Progress", "How far a run has gone, as passed to run(..., progress=callback).")
        .def_readonly("fraction", &Progress::fraction, "share of the run done, 0..1")
        .def_readonly("simulated_s", &Progress::simulated_s, "simulated time reached (s)")
        .def_readonly("elapsed_s", &Progress::elapsed_s, "wall time so far (s)")
        .def_readonly("remaining_s", &Progress::remaining_s, "estimated wall time left (s)")
        .def("__repr__", [](const Progress& p) {
            return "<fretbuzz.Progress " + std::to_string(100.0 * p.fraction) + "%>";
        });
    m.def(
        "audio_file_names",
        [](bool velocity, const std::vector<double>& points) {
            return audio_file_names(velocity ? AudioSignal::velocity : AudioSignal::displacement, points);
        },
        py::arg("velocity"), py::arg("points"), "The WAV file names a run writes for these observation points.");
    m.def("simulate", &simulate_case, py::arg("case"), py::kw_only(), py::arg("snapshots") = 0.0,
          py::arg("screen") = true, py::arg("free_flight") = true, py::arg("out") = py::none(),
          py::arg("velocity_audio") = false, py::arg("snapshot_until") = py::none(), py::arg("progress") = py::none(),
          py::arg("fade_in") = py::none(), py::arg("fade_out") = py::none(),
          "simulate(case: Case, *, snapshots=0.0, screen=True, free_flight=True, out=None, velocity_audio=False,\n"
          "         snapshot_until=None, progress=None, fade_in=None, fade_out=None) -> RecordedRun\n\n"
          "The compiled run behind fretbuzz.run(); see there.");
}

}  // namespace fretbuzz::python
