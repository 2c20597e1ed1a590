#pragma once
// Shared by the finger, gesture and pluck tests: the Jazz Bass of bass-pluck (its neck rebuilt by
// the fretboard generator) on 255 modes, so that runs of 1e5 steps take a second, and the
// comparison of the screened path with the straightforward one, step by step; an ideal string.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "TestSupport.hpp"

#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/run/ResultRecorder.hpp"
#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/Stepper.hpp"

namespace fretbuzz::testing {

// Plucked `amplitude` (m) at 0.637 m; 0 leaves the string at rest.
inline Case small_bass(double fs, double duration, double amplitude, std::size_t modes = 255) {
    std::string text = builtin_case_text("bass-pluck");
    // (N + 1 = 256: a fast sine transform)
    text.replace(text.find("modes = 862"), 11, "modes = " + std::to_string(modes));
    text.replace(text.find("amplitude = 0.5e-3"), 18, "amplitude = " + std::to_string(amplitude));
    Case c = parse_case(text, "small-bass.toml", DataSource::builtin());
    c.run.sample_rate_hz = fs;
    c.run.duration_s = duration;
    return c;
}

struct PathComparison {
    double relative_l2 = 0.0;  // of the modal state over every step
    long contact_steps = 0;    // on the screened path
    StepStatistics fast, plain;
};

// Steps a and b side by side for `steps` steps: the relative L2 of a's modal state against b's
// over every step.
inline double step_and_compare(Stepper& a, Stepper& b, long steps) {
    double num = 0.0, den = 0.0;
    for (long n = 0; n < steps; ++n) {
        a.step();
        b.step();
        const std::span<const double> qa = a.modal_displacement(), qb = b.modal_displacement();
        for (std::size_t j = 0; j < qb.size(); ++j) {
            num += (qa[j] - qb[j]) * (qa[j] - qb[j]);
            den += qb[j] * qb[j];
        }
    }
    return std::sqrt(num / den);
}

// Runs c screened and straightforward side by side for `steps` steps.
inline PathComparison compare_paths(const Case& c, long steps) {
    const Plan fast_plan(c, 1.0 / c.run.sample_rate_hz);
    PlanOptions plain_options;
    plain_options.screen_contacts = false;
    const Plan plain_plan(c, 1.0 / c.run.sample_rate_hz, plain_options);
    Stepper fast(fast_plan, c.initial_displacement, c.initial_velocity);
    Stepper plain(plain_plan, c.initial_displacement, c.initial_velocity);
    const double l2 = step_and_compare(fast, plain, steps);
    return {l2, fast.statistics().contact_steps, fast.statistics(), plain.statistics()};
}

// A whole run of c, recorded: its fast path (screening, free flight) or the straightforward one
// (every point solved and every mode stepped at every step); its energy balance within 1e-10.
inline RecordedRun record_run(const Case& c, bool fast) {
    ResultRecorder recorder;
    RunObserver* observers[] = {&recorder};
    RunOptions options;
    options.plan.screen_contacts = fast;
    options.plan.choose_screening = false;
    options.free_flight = fast;
    const RunSummary s = simulate(c, observers, options);
    EXPECT_LT(s.max_relative_balance_error, 1e-10);
    return recorder.take();
}

// An ideal string (L = mu = 1, tension T) with `modes` modes and the given obstacle and
// excitation lines (by default at rest).
inline Case ideal_string(std::size_t modes, double tension, const std::string& obstacle, double fs,
                         const std::string& excitation = "type = \"sine\"\nmode = 1\namplitude = 0.0") {
    const std::string text = R"(name = "ideal-string"
[string]
L = 1.0
T = )" + std::to_string(tension) + R"(
mu = 1.0
modes = )" + std::to_string(modes) + R"(
ideal = true
[obstacle]
)" + obstacle + R"(
[excitation]
)" + excitation + R"(
[contact]
K = 1e5
alpha = 1.5
[run]
fs = )" + std::to_string(fs) + R"(
duration = 1.0
lossless = true
[observe]
x = [0.7]
)";
    return parse_case(text, "ideal-string.toml", DataSource::builtin());
}

// u(x_obs) at every step of `steps`.
inline std::vector<double> observed(const Case& c, double x_obs, long steps) {
    c.validate();
    const Plan plan(c, 1.0 / c.run.sample_rate_hz);
    const std::vector<double> probe = plan.basis().mode_shapes_at(x_obs);
    Stepper s(plan, c.initial_displacement, c.initial_velocity);
    std::vector<double> u;
    for (long n = 0; n < steps; ++n) {
        s.step();
        u.push_back(s.displacement(probe));
    }
    return u;
}

// The small bass's case text at 100 kHz for 10 ms (for runs of the command line), and a
// check that each (extra text, key) is refused with exit 2 naming key and leaving no
// output (an empty key: the case runs).
inline std::string small_bass_text() {
    std::string base = builtin_case_text("bass-pluck");
    base.replace(base.find("modes = 862"), 11, "modes = 255");
    base.replace(base.find("fs = 1e6"), 8, "fs = 100000");
    base.replace(base.find("duration = 0.5"), 14, "duration = 0.01");
    return base;
}

inline void expect_refused(const char* scratch_name, const std::string& base,
                           const std::vector<std::pair<std::string, std::string>>& cases) {
    ScratchDir scratch(scratch_name);
    int k = 0;
    for (const auto& [extra, key] : cases) {
        std::string name = std::to_string(k++);
        name += ".toml";  // (appending, not "g" + ...: GCC 12 warns falsely on that form)
        const std::filesystem::path file = scratch.path() / name;
        std::ofstream(file) << base << extra;
        const std::filesystem::path out = scratch.path() / "out";
        const auto r = run_cli("run " + file.string() + " --out " + out.string() + " -q");
        if (key.empty()) {
            EXPECT_EQ(r.exit_code, 0) << r.output;
            std::filesystem::remove_all(out);
            continue;
        }
        EXPECT_EQ(r.exit_code, 2) << extra << r.output;
        EXPECT_NE(r.output.find(key), std::string::npos) << extra << " should name " << key << ": " << r.output;
        EXPECT_FALSE(std::filesystem::exists(out)) << extra;
    }
}

}  // namespace fretbuzz::testing
