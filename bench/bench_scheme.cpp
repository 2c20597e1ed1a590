// fretbuzz_bench: how fast is a simulation, and how much faster than the paper's dense
// form? Every variant runs the same case at the same rate in the same process:
//   Fast             the product's path (scheduled contact checks, free flight between
//                    contacts), a whole run with its audio output, as `fretbuzz run` does;
//   Straightforward  the modal scheme solving every point every step (sine transforms);
//   Dense            eq. (4) with D and D~ as full N x N matrices (two matrix-vector
//                    products per step), compiled with the same flags.
//   Window           the product's stepping over the same contact window as the two above;
//   Outputs/None     a 3 s bass-pop with every output file (CSV, WAV, HDF5 with the contact
//                    map) against the same run with no observer at all; PerStepAudio is
//                    Outputs with the audio resampled from the per-step signal throughout
//                    (no closed form in long flights: how outputs were written before).
//   Played           the open pop and the same pop stopped at fret 5 by a finger, whole runs
//                    of the same length side by side (the finger's cost on the fast path).
// Run with --benchmark_repetitions=5 (the default here) to get medians; the summary at the
// end gives microseconds per step, simulated seconds per wall second and the ratios.
// `fretbuzz_bench --scaling` instead prints the per-step cost against the mode count N,
// the sampling rate and the extent of the obstacle, with fitted exponents.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "fretbuzz/io/AudioWriter.hpp"
#include "fretbuzz/io/CaseFile.hpp"
#include "fretbuzz/io/RunOutputs.hpp"
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

// A whole 3 s bass-pop at 4 MHz, with every output file or with none.
void whole_run(benchmark::State& state, bool outputs, bool closed_form_audio) {
    Case c = load_case("bass-pop");
    c.run.duration_s = 3.0;
    const long steps = std::lround(c.run.sample_rate_hz * c.run.duration_s);
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "fretbuzz-bench-outputs";
    for (auto _ : state) {
        std::filesystem::remove_all(dir);
        if (outputs) {
            RunOutputs files(dir, c);
            RunOptions options;
            options.closed_form_audio = closed_form_audio;
            benchmark::DoNotOptimize(simulate(c, files.observers(), options).energy_final_j);
            files.commit();
        } else {
            benchmark::DoNotOptimize(simulate(c, {}).energy_final_j);
        }
    }
    std::filesystem::remove_all(dir);
    state.counters["us_per_step"] = benchmark::Counter(static_cast<double>(steps) * 1e-6,
                                                       benchmark::Counter::kIsIterationInvariantRate |
                                                           benchmark::Counter::kInvert);
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
            const double window_us = get("Window");
            const double wall_per_sim_s = fast_us * 1e-6 * b.fs;
            std::printf("  %-14s fs = %.0f Hz: fast %.4f us/step (%.3f s wall per simulated second, %.2f simulated s per wall s)\n",
                        b.name, b.fs, fast_us, wall_per_sim_s, 1.0 / wall_per_sim_s);
            std::printf("  %-14s straightforward %.2f us/step, dense %.1f us/step; fast is %.0fx faster than dense, %.0fx than straightforward\n",
                        "", plain_us, dense_us, dense_us / fast_us, plain_us / fast_us);
            std::printf("  %-14s contact window: fast %.2f us/step, %.0fx faster than dense, %.1fx than straightforward\n",
                        "", window_us, dense_us / window_us, plain_us / window_us);
        }
        const auto outputs = median_us_.find("Outputs/bass-pop-3s"), none = median_us_.find("None/bass-pop-3s");
        if (outputs != median_us_.end() && none != median_us_.end())
            std::printf("  bass-pop 3 s at 4 MHz: every output %.3f s, no output %.3f s (%.2fx)\n",
                        outputs->second * 12.0, none->second * 12.0, outputs->second / none->second);
        const auto per_step = median_us_.find("PerStepAudio/bass-pop-3s");
        if (per_step != median_us_.end() && none != median_us_.end())
            std::printf("  %-14s every output, audio resampled from every step: %.3f s (%.2fx no output)\n", "",
                        per_step->second * 12.0, per_step->second / none->second);
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

// --- Scaling table ---------------------------------------------------------------------
// A tanpura-like string (model modes, so N can be anything) plucked against an obstacle of
// three extents: one point, 20 fret-like points, and a flat obstacle along the whole string.
// Whole runs of 20 ms (several contacts) through the product's path with no observer.
std::string scaling_case_text(std::size_t modes, double fs, const std::string& extent) {
    std::string text = builtin_case_text("tanpura");
    auto replace_section = [&](const std::string& header, const std::string& body) {
        const std::size_t at = text.find(header);
        const std::size_t end = text.find("\n[", at + 1);
        text.replace(at, end - at, header + "\n" + body);
    };
    const std::size_t key = text.find("modes = 400");
    text.replace(key, 11, "modes = " + std::to_string(modes));
    if (extent == "frets") {
        std::string x = "x = [", h = "height = -0.0003";
        for (int k = 1; k <= 20; ++k) x += std::to_string(0.04 * k) + (k < 20 ? ", " : "]");
        replace_section("[obstacle]", "type = \"points\"\n" + x + "\n" + h + "\n");
    } else if (extent == "flat") {
        replace_section("[obstacle]", "type = \"flat\"\nheight = -0.0003\n");
    }
    replace_section("[run]", "fs = " + std::to_string(fs) + "\nduration = 0.02\nallow_aliasing = true\n");
    return text;
}

double median_us_per_step(std::size_t modes, double fs, const std::string& extent, int repetitions) {
    const Case c = parse_case(scaling_case_text(modes, fs, extent), "scaling", DataSource::builtin());
    const double steps = std::round(c.run.duration_s * fs);
    std::vector<double> us;
    for (int r = 0; r < repetitions; ++r) {
        const auto start = std::chrono::steady_clock::now();
        benchmark::DoNotOptimize(simulate(c, {}).energy_final_j);
        us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count() / steps);
    }
    std::sort(us.begin(), us.end());
    return us[us.size() / 2];
}

// Least-squares slope of log(cost) against log(x).
double fitted_exponent(const std::vector<double>& x, const std::vector<double>& cost) {
    double mx = 0.0, my = 0.0;
    for (std::size_t k = 0; k < x.size(); ++k) {
        mx += std::log(x[k]) / static_cast<double>(x.size());
        my += std::log(cost[k]) / static_cast<double>(x.size());
    }
    double sxy = 0.0, sxx = 0.0;
    for (std::size_t k = 0; k < x.size(); ++k) {
        sxy += (std::log(x[k]) - mx) * (std::log(cost[k]) - my);
        sxx += (std::log(x[k]) - mx) * (std::log(x[k]) - mx);
    }
    return sxy / sxx;
}

int print_scaling_table() {
    const std::vector<std::string> extents = {"point", "frets", "flat"};
    const int repetitions = 3;
    const std::vector<double> modes = {100, 200, 400, 800, 1600, 3200};
    std::printf("Per-step cost, us (median of %d whole 20 ms runs, no output), fs = 400 kHz\n", repetitions);
    std::printf("| N | point | frets | flat |\n|---|---|---|---|\n");
    std::map<std::string, std::vector<double>> by_n;
    for (double n : modes) {
        std::printf("| %.0f |", n);
        for (const std::string& e : extents) {
            by_n[e].push_back(median_us_per_step(static_cast<std::size_t>(n), 4e5, e, repetitions));
            std::printf(" %.3f |", by_n[e].back());
            std::fflush(stdout);
        }
        std::printf("\n");
    }
    std::printf("| exponent in N |");
    for (const std::string& e : extents) std::printf(" %.2f |", fitted_exponent(modes, by_n[e]));
    const std::vector<double> rates = {48e3, 96e3, 192e3, 384e3, 768e3, 1536e3};
    std::printf("\n\nPer-step cost, us, N = 400\n| fs (kHz) | point | frets | flat |\n|---|---|---|---|\n");
    std::map<std::string, std::vector<double>> by_fs;
    for (double fs : rates) {
        std::printf("| %.0f |", fs / 1e3);
        for (const std::string& e : extents) {
            by_fs[e].push_back(median_us_per_step(400, fs, e, repetitions));
            std::printf(" %.3f |", by_fs[e].back());
            std::fflush(stdout);
        }
        std::printf("\n");
    }
    std::printf("| exponent in fs |");
    for (const std::string& e : extents) std::printf(" %.2f |", fitted_exponent(rates, by_fs[e]));
    std::printf("\n");
    return 0;
}

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
        benchmark::RegisterBenchmark(("Window" + suffix).c_str(), per_step<Stepper>, b, warmup, 2000L, true)
            ->Unit(benchmark::kMillisecond)
            ->Iterations(2)
            ->UseRealTime();
        benchmark::RegisterBenchmark(("Dense" + suffix).c_str(), per_step<DenseMatrixScheme>, b, warmup, 200L, false)
            ->Unit(benchmark::kMillisecond)
            ->Iterations(2)
            ->UseRealTime();
    }
    for (const auto& [name, outputs, closed_form] : {std::tuple{"Outputs/bass-pop-3s", true, true},
                                                     std::tuple{"PerStepAudio/bass-pop-3s", true, false},
                                                     std::tuple{"None/bass-pop-3s", false, true}})
        benchmark::RegisterBenchmark(name, whole_run, outputs, closed_form)
            ->Unit(benchmark::kMillisecond)
            ->Iterations(1)
            ->UseRealTime();
    for (const BenchCase& b : kPlayed)
        benchmark::RegisterBenchmark((std::string("Played/") + b.name).c_str(), fast, b)
            ->Unit(benchmark::kMillisecond)
            ->Iterations(1)
            ->UseRealTime();
    for (int i = 1; i < argc; ++i)
        if (std::string(argv[i]) == "--scaling") return print_scaling_table();
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
