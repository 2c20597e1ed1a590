// fretbuzz_bench: how fast is a simulation, and how much faster than the paper's dense
// form? Every variant runs the same case at the same rate in the same process:
//   Fast             the product's path (scheduled contact checks, free flight between
//                    contacts), a whole run with its audio output, as `fretbuzz run` does;
//   Straightforward  the modal scheme solving every point every step (sine transforms);
//   Dense            eq. (4) with D and D~ as full N x N matrices (two matrix-vector
//                    products per step), compiled with the same flags.
//   Played           the open pop and the same pop stopped at fret 5 by a finger, whole runs
//                    of the same length side by side (the finger's cost on the fast path).
// Run with --benchmark_repetitions=5 (the default here) to get medians; the summary at the
// end gives microseconds per step, simulated seconds per wall second and the ratios.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "fretbuzz/io/AudioWriter.hpp"
#include "fretbuzz/io/CaseFile.hpp"
#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/scheme/DenseMatrixScheme.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/Stepper.hpp"

namespace {

using namespace fretbuzz;

struct BenchCase {
    const char* name;
    double fs;
    double duration;  // simulated seconds for the fast path
};

const BenchCase kCases[] = {{"bass-pop", 4e6, 1.0}, {"flat-obstacle", 1e4, 4.0}};
// The open pop against the fretted pop over the same 0.3 s (the fretted run has no
// stretch free of contact: about 45 s per simulated second).
const BenchCase kPlayed[] = {{"bass-pop", 4e6, 0.3}, {"bass-fret5-pop", 4e6, 0.3}};

Case prepared(const BenchCase& b) {
    Case c = load_case(b.name);
    c.run.sample_rate_hz = b.fs;
    c.run.duration_s = b.duration;
    return c;
}

// A sink that keeps the audio path honest (resampling every step) without writing files.
class AudioSink : public AudioWriter {
public:
    explicit AudioSink(double rate) : AudioWriter({"/dev/null"}, rate) {}
    void finish(const RunSummary&) override {}
};

void fast(benchmark::State& state, BenchCase b) {
    const Case c = prepared(b);
    const long steps = std::lround(b.fs * b.duration);
    for (auto _ : state) {
        AudioSink audio(c.run.audio_rate_hz);
        RunObserver* observers[] = {&audio};
        benchmark::DoNotOptimize(simulate(c, observers).energy_final_j);
    }
    state.counters["us_per_step"] = benchmark::Counter(static_cast<double>(steps) * 1e-6,
                                                       benchmark::Counter::kIsIterationInvariantRate |
                                                           benchmark::Counter::kInvert);
    state.counters["steps"] = static_cast<double>(steps);
}

// Per-step timings of the reference paths over a window that includes contacts.
template <typename Scheme>
void per_step(benchmark::State& state, BenchCase b, long warmup_steps, long steps, bool screen) {
    const Case c = prepared(b);
    PlanOptions options;
    options.screen_contacts = screen;
    const Plan plan(c, 1.0 / b.fs, options);
    auto make = [&] {
        if constexpr (std::is_same_v<Scheme, Stepper>)
            return Stepper(plan, c.initial_displacement, c.initial_velocity);
        else
            return DenseMatrixScheme(c, 1.0 / b.fs);
    };
    Scheme start = make();  // set up once (the dense matrices take a while)
    for (long n = 0; n < warmup_steps; ++n) start.step();
    for (auto _ : state) {
        state.PauseTiming();
        Scheme scheme = start;
        state.ResumeTiming();
        for (long n = 0; n < steps; ++n) scheme.step();
    }
    state.counters["us_per_step"] = benchmark::Counter(static_cast<double>(steps) * 1e-6,
                                                       benchmark::Counter::kIsIterationInvariantRate |
                                                           benchmark::Counter::kInvert);
}

// Collects the medians to print the side-by-side summary.
class SummaryReporter : public benchmark::ConsoleReporter {
public:
    void ReportRuns(const std::vector<Run>& runs) override {
        ConsoleReporter::ReportRuns(runs);
        for (const Run& run : runs) {
            if (run.aggregate_name != "median") continue;
            const auto it = run.counters.find("us_per_step");
            if (it != run.counters.end()) median_us_[run.run_name.function_name] = it->second.value;
        }
    }
    void print_summary() const {
        std::printf("\nSummary (medians):\n");
        for (const BenchCase& b : kCases) {
            const std::string name = b.name;
            const auto get = [&](const std::string& variant) {
                const auto it = median_us_.find(variant + "/" + name);
                return it == median_us_.end() ? std::nan("") : it->second;
            };
            const double fast_us = get("Fast"), plain_us = get("Straightforward"), dense_us = get("Dense");
            const double wall_per_sim_s = fast_us * 1e-6 * b.fs;
            std::printf("  %-14s fs = %.0f Hz: fast %.4f us/step (%.3f s wall per simulated second, %.2f simulated s per wall s)\n",
                        b.name, b.fs, fast_us, wall_per_sim_s, 1.0 / wall_per_sim_s);
            std::printf("  %-14s straightforward %.2f us/step, dense %.1f us/step; fast is %.0fx faster than dense, %.0fx than straightforward\n",
                        "", plain_us, dense_us, dense_us / fast_us, plain_us / fast_us);
        }
        const auto played = [&](const char* name) {
            const auto it = median_us_.find(std::string("Played/") + name);
            return it == median_us_.end() ? std::nan("") : it->second;
        };
        const double open_us = played(kPlayed[0].name), fretted_us = played(kPlayed[1].name);
        std::printf("  played, %.1f s at %.0f Hz: open pop %.4f us/step, fretted pop (fret 5) %.4f us/step: %.1fx the open pop's time\n",
                    kPlayed[0].duration, kPlayed[0].fs, open_us, fretted_us, fretted_us / open_us);
    }

private:
    std::map<std::string, double> median_us_;
};

}  // namespace

int main(int argc, char** argv) {
    for (const BenchCase& b : kCases) {
        const std::string suffix = std::string("/") + b.name;
        benchmark::RegisterBenchmark(("Fast" + suffix).c_str(), fast, b)
            ->Unit(benchmark::kMillisecond)
            ->Iterations(1)
            ->UseRealTime();
        // Reference paths: 2000 steps from where the string is about to hit (bass: 3.7 ms).
        const long warmup = std::string(b.name) == "bass-pop" ? 14800 : 9000;
        benchmark::RegisterBenchmark(("Straightforward" + suffix).c_str(), per_step<Stepper>, b, warmup, 2000L, false)
            ->Unit(benchmark::kMillisecond)
            ->Iterations(2)
            ->UseRealTime();
        benchmark::RegisterBenchmark(("Dense" + suffix).c_str(), per_step<DenseMatrixScheme>, b, warmup, 200L, false)
            ->Unit(benchmark::kMillisecond)
            ->Iterations(2)
            ->UseRealTime();
    }
    for (const BenchCase& b : kPlayed)
        benchmark::RegisterBenchmark((std::string("Played/") + b.name).c_str(), fast, b)
            ->Unit(benchmark::kMillisecond)
            ->Iterations(1)
            ->UseRealTime();
    std::vector<char*> args(argv, argv + argc);
    std::string repetitions = "--benchmark_repetitions=5";
    bool has_repetitions = false;
    for (int i = 1; i < argc; ++i) has_repetitions |= std::string(argv[i]).rfind("--benchmark_repetitions", 0) == 0;
    if (!has_repetitions) args.push_back(repetitions.data());
    int count = static_cast<int>(args.size());
    benchmark::Initialize(&count, args.data());
    SummaryReporter reporter;
    benchmark::RunSpecifiedBenchmarks(&reporter);
    reporter.print_summary();
    benchmark::Shutdown();
    return 0;
}
