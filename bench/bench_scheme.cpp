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
//   Played           the open pop and the pop stopped at fret 5 by a finger (popped at 20 ms), whole runs
//                    of the same length side by side (the finger's cost on the fast path).
//   Decayed          the bass pop's string stepped from a fully decayed state (every coordinate
//                    subnormal, as its high modes are after a second or two), plain and with
//                    subnormals flushed as every run does: the cost of subnormal arithmetic on
//                    this processor (none on some, about a hundred cycles a product on others).
// Run with --benchmark_repetitions=5 (the default here) to get medians; the summary at the
// end gives microseconds per step, simulated seconds per wall second and the ratios.
// `fretbuzz_bench --scaling` instead prints the per-step cost against the mode count N,
// the sampling rate and the extent of the obstacle, with fitted exponents;
// `fretbuzz_bench --contact [repetitions] [text]` the cost of contact steps and of audio-rate
// runs, and of the passes that bound them from below (see print_contact_table and
// print_floors: the engine's tanpura, a 120-mode bridge, a fretted pop); with text, only the
// rows whose label contains it. Outputs/None also report the CPU time of every thread, whose
// half bounds the every-output run's wall time on a 2-core machine.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "fretbuzz/SubnormalFlush.hpp"
#include "fretbuzz/output/AudioWriter.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/output/RunOutputs.hpp"
#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/scheme/DenseMatrixScheme.hpp"
#include "fretbuzz/numerics/Kernels.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/SamplingCheck.hpp"
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
// stretch free of contact: it is stepped whole).
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
void whole_run(benchmark::State& state, const char* case_name, bool outputs, bool closed_form_audio) {
    Case c = load_case(case_name);
    c.run.duration_s = 3.0;
    const long steps = std::lround(c.run.sample_rate_hz * c.run.duration_s);
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "fretbuzz-bench-outputs";
    // The CPU time of every thread (the writers' too): over 2 cores a run takes at least half of it.
    const auto process_cpu_s = [] {
        timespec t{};
        clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
        return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
    };
    const double cpu_start = process_cpu_s();
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
    state.counters["process_cpu_s"] = benchmark::Counter(process_cpu_s() - cpu_start, benchmark::Counter::kAvgIterations);
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
    double points = 0.0, contact_steps = 0.0;
    for (auto _ : state) {
        state.PauseTiming();
        Scheme scheme = start;
        state.ResumeTiming();
        for (long n = 0; n < steps; ++n) scheme.step();
        if constexpr (std::is_same_v<Scheme, Stepper>) {
            points = scheme.statistics().points_solved - start.statistics().points_solved;
            contact_steps = static_cast<double>(scheme.statistics().contact_steps - start.statistics().contact_steps);
        }
    }
    if constexpr (std::is_same_v<Scheme, Stepper>) {
        state.counters["points_per_step"] = points / static_cast<double>(steps);
        state.counters["contact_steps"] = contact_steps;
    }
    state.counters["us_per_step"] = benchmark::Counter(static_cast<double>(steps) * 1e-6,
                                                       benchmark::Counter::kIsIterationInvariantRate |
                                                           benchmark::Counter::kInvert);
}

// 20 000 steps of the bass pop's string (862 modes, 4 MHz) from a state whose every coordinate
// is subnormal: the pass over the modes on subnormal inputs, plain or flushed.
void decayed(benchmark::State& state, bool flushed) {
    const Case c = load_case("bass-pop");
    const Plan plan(c, 1.0 / c.run.sample_rate_hz);
    std::vector<double> q0(c.mode_count()), v0(c.mode_count(), 0.0);
    for (std::size_t j = 0; j < q0.size(); ++j) q0[j] = 1e-310 * std::cos(0.7 * static_cast<double>(j));
    Stepper start(plan, q0, v0);
    start.step();
    constexpr long kSteps = 20000;
    std::size_t subnormal = 0;
    for (auto _ : state) {
        state.PauseTiming();
        Stepper string = start;
        state.ResumeTiming();
        if (flushed) {
            const SubnormalFlush guard;
            for (long n = 0; n < kSteps; ++n) string.step();
        } else {
            for (long n = 0; n < kSteps; ++n) string.step();
        }
        subnormal = string.subnormal_coordinates();
    }
    state.counters["subnormal_coordinates"] = static_cast<double>(subnormal);
    state.counters["us_per_step"] = benchmark::Counter(static_cast<double>(kSteps) * 1e-6,
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
            const auto cpu = run.counters.find("process_cpu_s");
            if (cpu != run.counters.end()) median_cpu_s_[run.run_name.function_name] = cpu->second.value;
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
            if (std::isnan(fast_us)) continue;  // filtered out of this run
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
        if (outputs != median_us_.end() && none != median_us_.end() && median_cpu_s_.contains("Outputs/bass-pop-3s")) {
            // However the output work were spread over this machine's 2 cores, the run would take
            // at least half its CPU time: the floor on the every-output/no-output ratio today.
            const double cpu = median_cpu_s_.at("Outputs/bass-pop-3s");
            std::printf("  %-14s every output: %.3f s CPU in all threads, so at least %.3f s on 2 cores (%.2fx no output)\n",
                        "", cpu, 0.5 * cpu, 0.5 * cpu / (none->second * 12.0));
        }
        const auto per_step = median_us_.find("PerStepAudio/bass-pop-3s");
        if (per_step != median_us_.end() && none != median_us_.end())
            std::printf("  %-14s every output, audio resampled from every step: %.3f s (%.2fx no output)\n", "",
                        per_step->second * 12.0, per_step->second / none->second);
        const auto played = [&](const char* name) {
            const auto it = median_us_.find(std::string("Played/") + name);
            return it == median_us_.end() ? std::nan("") : it->second;
        };
        const double open_us = played(kPlayed[0].name), fretted_us = played(kPlayed[1].name);
        if (!std::isnan(open_us) && !std::isnan(fretted_us))
            std::printf("  played, %.1f s at %.0f Hz: open pop %.4f us/step, fretted pop (fret 5) %.4f us/step: %.1fx the open pop's time\n",
                        kPlayed[0].duration, kPlayed[0].fs, open_us, fretted_us, fretted_us / open_us);
        const auto plain = median_us_.find("Decayed/bass-pop/plain"), flushed = median_us_.find("Decayed/bass-pop/flushed");
        if (plain != median_us_.end() && flushed != median_us_.end())
            std::printf("  decayed state (every coordinate subnormal), bass pop's string: plain %.4f us/step, flushed %.4f us/step: %.2fx\n",
                        plain->second, flushed->second, plain->second / flushed->second);
    }

private:
    std::map<std::string, double> median_us_;
    std::map<std::string, double> median_cpu_s_;
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

// --- Contact steps -----------------------------------------------------------------------
// `fretbuzz_bench --contact`: the cost of steps with contact (windows of the bass pop, the
// flat obstacle at its onset, the audio-rate instruments) and of whole audio-rate runs
// stepping only; thread CPU time (what the step costs, whatever else the machine runs) and
// wall time, medians over the repetitions. Compare builds by running each in turn.
struct Timing {
    double cpu_s = 0.0, wall_s = 0.0;
};

template <class F>
Timing timed(F&& f) {
    timespec c0{}, c1{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &c0);
    const auto w0 = std::chrono::steady_clock::now();
    f();
    const auto w1 = std::chrono::steady_clock::now();
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &c1);
    return {static_cast<double>(c1.tv_sec - c0.tv_sec) + 1e-9 * static_cast<double>(c1.tv_nsec - c0.tv_nsec),
            std::chrono::duration<double>(w1 - w0).count()};
}

double median_of(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

// A case at an audio rate with only its modes below fs/2 (as `fretbuzz run --fs` keeps them).
Case in_band(const std::string& name, double fs, std::size_t modes = 0) {
    const std::size_t kept = modes > 0 ? modes : modes_below_nyquist(load_case(name).modes, fs);
    Case c = with_mode_count(read_case_text(name), kept);
    c.run.sample_rate_hz = fs;
    return c;
}

// The first step with a contact force, stepping from the start.
long first_contact_step(const Case& c, double fs) {
    const Plan plan(c, 1.0 / fs);
    Stepper s(plan, c.initial_displacement, c.initial_velocity);
    while (s.statistics().contact_steps == 0 && s.step_index() < 100000000L) s.step();
    return s.step_index();
}

// The one pass over the modes that a step with contact cannot skip (the step itself, with the
// points it pushes and the rows the next step predicts, as Stepper's fused pass forms them),
// timed alone, and the bound it sets on three targets: a string resting on a bridge steps
// every sample in full (no free flight), and so does a string a finger holds on a fret.
struct FloorRow {
    std::string label;
    Case c;
    double fs;
    std::size_t pushes, predicted;  // rows pushed and predicted, from the middle of the string
    bool pickup;
};

template <class Wanted>
void print_floors(int repetitions, const Wanted& wanted) {
    std::vector<FloorRow> rows;
    rows.push_back({"tanpura at 8x (the engine's 400 modes, 384 kHz)", with_mode_count(read_case_text("tanpura"), 400),
                    8 * 48000.0, 1, 1, true});
    rows.push_back({"sitar bridge, 120 modes, 48 kHz", in_band("sitar", 48000.0, 120), 48000.0, 1, 1, false});
    {
        // The pad's points and the fret under it, pushed and predicted at every step.
        const Case fretted = load_case("bass-fret5-pop");
        const Plan plan(fretted, 1.0 / 4e6);
        const Stepper s(plan, fretted.initial_displacement, fretted.initial_velocity);
        const std::size_t pad = s.fingers().empty() ? 0 : s.fingers().front().pad().size();
        rows.push_back({"bass-fret5-pop (862 modes, 4 MHz), the finger's " + std::to_string(pad) + "-point pad and its fret",
                        fretted, 4e6, pad + 1, pad + 1, true});
    }
    std::printf("\nFloors: the step's one pass alone, us, medians of %d (of 2000 calls each), and what it bounds\n",
                repetitions);
    std::printf("| pass | pushes / predicted rows | CPU | bound |\n|---|---|---|---|\n");
    for (const FloorRow& row : rows) {
        if (!wanted(row.label)) continue;
        const Plan plan(row.c, 1.0 / row.fs);
        const ModalPropagator& p = plan.propagator();
        const std::size_t n = plan.mode_count();
        std::vector<double> q(row.c.initial_displacement.begin(), row.c.initial_displacement.end()), d(n, 0.0);
        std::vector<const double*> pushed, predicted;
        std::vector<double> coefficients(row.pushes, 1e-30), forecast(row.predicted, 0.0);
        for (std::size_t r = 0; r < row.pushes; ++r) pushed.push_back(plan.basis().row(n / 2 + r).data());
        for (std::size_t r = 0; r < row.predicted; ++r) predicted.push_back(plan.basis().row(n / 2 + r).data());
        const double* pickup = plan.basis().row(n / 5).data();
        double observed = 0.0;
        kernels::StepPass pass;
        pass.push_rows = pushed.data();
        pass.push_coefficients = coefficients.data();
        pass.pushes = row.pushes;
        pass.predict_rows = predicted.data();
        pass.predict_count = row.predicted;
        pass.predicted = forecast.data();
        if (row.pickup) {
            pass.observe_row = pickup;
            pass.observed = &observed;
        }
        const double* loss = p.lossless() ? nullptr : p.loss().data();
        std::vector<double> cpu;
        constexpr int kCalls = 2000;
        for (int r = 0; r < repetitions; ++r) {
            const Timing t = timed([&] {
                for (int k = 0; k < kCalls; ++k)
                    benchmark::DoNotOptimize(plan.step_kernel()(p.decay().data(), p.beta().data(), loss, pass, q.data(),
                                                                d.data(), n));
            });
            cpu.push_back(t.cpu_s * 1e6 / kCalls);
        }
        benchmark::DoNotOptimize(observed);
        const double us = median_of(cpu);
        char bound[160];
        if (row.fs > 1e6)  // a fretted pop: its 3 s at 4 MHz, every step this pass
            std::snprintf(bound, sizeof bound, "3 s: at least %.2f s of passes", us * 1e-6 * row.fs * 3.0);
        else if (row.pickup)  // the engine: 8 internal steps per host sample
            std::snprintf(bound, sizeof bound, "at most %.0fx real time", 1.0 / (us * 1e-6 * row.fs));
        else
            std::snprintf(bound, sizeof bound, "at least %.4f s per simulated s", us * 1e-6 * row.fs);
        std::printf("| %s | %zu / %zu | %.3f | %s |\n", row.label.c_str(), row.pushes, row.predicted, us, bound);
        std::fflush(stdout);
    }
}

struct ContactRow {
    std::string label;
    Case c;
    double fs;
    long from, steps;  // stepping window: steps [from, from + steps)
};

int print_contact_table(int repetitions, const std::string& only) {
    const auto wanted = [&](const std::string& label) { return label.find(only) != std::string::npos; };
    std::vector<ContactRow> rows;
    rows.push_back({"bass-pop, 4 MHz, 862 modes, window", load_case("bass-pop"), 4e6, 14800, 2000});
    const Case flat = load_case("flat-obstacle");
    const long onset = first_contact_step(flat, 1e4);
    rows.push_back({"flat-obstacle, 10 kHz, window", flat, 1e4, 9000, 2000});
    rows.push_back({"flat-obstacle, 10 kHz, onset (20 steps)", flat, 1e4, onset - 1, 20});
    for (const char* name : {"tanpura", "sitar"}) {
        Case c = in_band(name, 48000.0);
        rows.push_back({std::string(name) + ", 48 kHz, " + std::to_string(c.mode_count()) + " modes, 0.1 s", c, 48000.0,
                        1, 4800});
    }
    std::printf("Steps with contact: us per step, medians of %d repetitions (thread CPU / wall)\n", repetitions);
    std::printf("| window | points/step | CPU | wall |\n|---|---|---|---|\n");
    for (const ContactRow& row : rows) {
        if (!wanted(row.label)) continue;
        const Plan plan(row.c, 1.0 / row.fs);
        Stepper start(plan, row.c.initial_displacement, row.c.initial_velocity);
        for (long n = 0; n < row.from; ++n) start.step();
        std::vector<double> cpu, wall;
        double points = 0.0;
        for (int r = 0; r < repetitions; ++r) {
            Stepper s = start;
            const Timing t = timed([&] {
                for (long n = 0; n < row.steps; ++n) s.step();
            });
            cpu.push_back(t.cpu_s * 1e6 / static_cast<double>(row.steps));
            wall.push_back(t.wall_s * 1e6 / static_cast<double>(row.steps));
            points = (s.statistics().points_solved - start.statistics().points_solved) / static_cast<double>(row.steps);
        }
        std::printf("| %s | %.1f | %.3f | %.3f |\n", row.label.c_str(), points, median_of(cpu), median_of(wall));
        std::fflush(stdout);
    }
    // Stepping only, whole runs: the audio-rate instruments and a 120-mode string on a bridge.
    std::printf("\nWhole runs with no output (stepping only), s per simulated second, medians of %d\n", repetitions);
    std::printf("| run | CPU | wall |\n|---|---|---|\n");
    std::vector<std::pair<std::string, Case>> runs;
    for (const char* name : {"tanpura", "sitar"}) {
        Case c = in_band(name, 48000.0);
        c.run.duration_s = 1.0;
        runs.emplace_back(std::string(name) + ", 48 kHz, " + std::to_string(c.mode_count()) + " modes, 1 s", c);
    }
    Case bridge = in_band("sitar", 48000.0, 120);
    bridge.run.duration_s = 1.0;
    runs.emplace_back("sitar bridge, 48 kHz, 120 modes, 1 s", bridge);
    for (const auto& [label, c] : runs) {
        if (!wanted(label)) continue;
        std::vector<double> cpu, wall;
        for (int r = 0; r < repetitions; ++r) {
            const Timing t = timed([&] { benchmark::DoNotOptimize(simulate(c, {}).energy_final_j); });
            cpu.push_back(t.cpu_s / c.run.duration_s);
            wall.push_back(t.wall_s / c.run.duration_s);
        }
        std::printf("| %s | %.4f | %.4f |\n", label.c_str(), median_of(cpu), median_of(wall));
        std::fflush(stdout);
    }
    // Passes no contact step can skip: what bounds the rows above from below.
    std::printf("\nOne pass, us, medians of %d (of 2000 calls each)\n", repetitions);
    std::printf("| pass | CPU | wall |\n|---|---|---|\n");
    for (const auto& [name, fs] : {std::pair{"flat-obstacle", 1e4}, std::pair{"bass-pop", 4e6}}) {
        const Case c = load_case(name);
        const Plan plan(c, 1.0 / fs);
        const std::size_t n = plan.mode_count();
        std::vector<double> q(c.initial_displacement.begin(), c.initial_displacement.end()), d(n, 0.0), out(n, 0.0);
        const auto pass = [&](const std::string& label, auto&& f) {
            if (!wanted(label)) return;
            std::vector<double> cpu, wall;
            constexpr int kCalls = 2000;
            for (int r = 0; r < repetitions; ++r) {
                const Timing t = timed([&] {
                    for (int k = 0; k < kCalls; ++k) f();
                });
                cpu.push_back(t.cpu_s * 1e6 / kCalls);
                wall.push_back(t.wall_s * 1e6 / kCalls);
            }
            benchmark::DoNotOptimize(out.data());
            std::printf("| %s | %.3f | %.3f |\n", label.c_str(), median_of(cpu), median_of(wall));
        };
        const std::string size = std::string(name) + ", " + std::to_string(n) + " modes";
        pass("sine transform (to the grid), " + size, [&] { plan.basis().to_grid(q, out); });
        pass("free amplitudes (speed bound), " + size, [&] { plan.propagator().free_amplitudes(q, d, out); });
        pass("one row product, " + size, [&] { out[0] += kernels::dot(plan.basis().row(n / 3).data(), q.data(), n); });
    }
    print_floors(repetitions, wanted);
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
    // The same 3 s pop against rigid frets (the impact law, bass-rigid-frets) beside the penalty's.
    for (const auto& [name, case_name, outputs, closed_form] :
         {std::tuple{"Outputs/bass-pop-3s", "bass-pop", true, true},
          std::tuple{"PerStepAudio/bass-pop-3s", "bass-pop", true, false},
          std::tuple{"None/bass-pop-3s", "bass-pop", false, true},
          std::tuple{"Outputs/bass-rigid-frets-3s", "bass-rigid-frets", true, true},
          std::tuple{"None/bass-rigid-frets-3s", "bass-rigid-frets", false, true}})
        benchmark::RegisterBenchmark(name, whole_run, case_name, outputs, closed_form)
            ->Unit(benchmark::kMillisecond)
            ->Iterations(1)
            ->UseRealTime();
    for (const BenchCase& b : kPlayed)
        benchmark::RegisterBenchmark((std::string("Played/") + b.name).c_str(), fast, b)
            ->Unit(benchmark::kMillisecond)
            ->Iterations(1)
            ->UseRealTime();
    for (const auto& [name, flushed] : {std::pair{"Decayed/bass-pop/plain", false}, std::pair{"Decayed/bass-pop/flushed", true}})
        benchmark::RegisterBenchmark(name, decayed, flushed)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();
    for (int i = 1; i < argc; ++i) {
        if (std::string(argv[i]) == "--scaling") return print_scaling_table();
        if (std::string(argv[i]) == "--contact")
            return print_contact_table(i + 1 < argc ? std::atoi(argv[i + 1]) : 9, i + 2 < argc ? argv[i + 2] : "");
    }
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
