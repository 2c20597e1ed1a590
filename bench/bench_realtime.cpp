// fretbuzz_bench_realtime: how much faster than real time does the real-time engine run, and
// how long is its worst block? Each benchmark renders one second of audio at 48 kHz in blocks
// of 256 samples, struck at the start of every iteration, one thread; times are the thread's
// CPU time (the machine is shared: wall time would count other processes). Side by side:
// the engine as shipped (free flight between contacts) and the same engine stepping every
// mode every step (the straightforward path). Counters (medians over the repetitions):
//   x_realtime      audio seconds per CPU second
//   worst_block_pct the longest single 256-sample block (CPU time), in % of its 5.33 ms
#include <benchmark/benchmark.h>

#include <algorithm>
#include <ctime>
#include <memory>
#include <vector>

#include "fretbuzz/io/CaseFile.hpp"
#include "fretbuzz/realtime/Engine.hpp"
#include "fretbuzz/realtime/StoppedString.hpp"

namespace {

using namespace fretbuzz;

constexpr double kRate = 48000.0;
constexpr std::size_t kBlock = 256;

struct Voice {
    const char* name;
    int fret;
    double pluck;  // fraction of the sounding length
};

// CPU time of this thread: on a shared machine, wall time also counts other processes' turns.
double thread_seconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

std::unique_ptr<Engine> make_voice(const Voice& v, bool free_flight, int max_oversampling) {
    const Case open = load_case(v.name);
    EngineOptions o;
    o.host_rate_hz = kRate;
    o.free_flight = free_flight;
    o.max_oversampling = max_oversampling;
    const Case c = v.fret == 0 ? open : stopped_string(open, fret_position(open.string.length_m, v.fret), open.mode_count());
    return std::make_unique<Engine>(c, o);
}

void render(benchmark::State& state, std::vector<Voice> voices, bool free_flight, int max_oversampling) {
    std::vector<std::unique_ptr<Engine>> engines;
    for (const Voice& v : voices) engines.push_back(make_voice(v, free_flight, max_oversampling));
    std::vector<float> block(kBlock);
    const long blocks = static_cast<long>(kRate) / static_cast<long>(kBlock);
    double worst = 0.0;
    for (auto _ : state) {
        for (std::size_t i = 0; i < engines.size(); ++i)
            engines[i]->strike({voices[i].pluck * engines[i]->length_m(), 1.0, 0.01, false});
        for (long b = 0; b < blocks; ++b) {
            const double t0 = thread_seconds();
            for (auto& e : engines) e->process(block);
            worst = std::max(worst, thread_seconds() - t0);
            benchmark::DoNotOptimize(block.data());
        }
    }
    const double audio_seconds = static_cast<double>(blocks * static_cast<long>(kBlock)) / kRate;
    state.counters["x_realtime"] =
        benchmark::Counter(audio_seconds, benchmark::Counter::kIsIterationInvariantRate);
    state.counters["worst_block_pct"] = 100.0 * worst / (static_cast<double>(kBlock) / kRate);
    state.counters["modes"] = static_cast<double>(engines.front()->mode_count());
    state.counters["oversampling"] = engines.front()->oversampling();
    state.counters["latency_samples"] = engines.front()->latency_samples();
}

void register_all() {
    const std::vector<Voice> chord = {{"guitar-point", 0, 0.8}, {"guitar-point", 2, 0.8}, {"guitar-point", 2, 0.8},
                                      {"guitar-point", 1, 0.8}, {"guitar-point", 0, 0.8}, {"guitar-point", 3, 0.8}};
    // The default (every mode kept, at most 8x oversampling: the accuracy the buzz needs, see
    // fretbuzz_rate_accuracy), and at most 4x and 2x: fewer modes (those below 86 and 43 kHz at
    // 48 kHz) at a lower rate, faster but changing the buzz by 2-6 dB.
    const struct {
        const char* label;
        std::vector<Voice> voices;
        int max_oversampling;
    } sets[] = {
        {"tanpura", {{"tanpura", 0, 0.3}}, 8},
        {"sitar", {{"sitar", 0, 0.3}}, 8},
        {"bass_fret5", {{"bass-pluck", 5, 0.8}}, 8},
        {"guitar_chord_6_voices", chord, 8},
        {"tanpura_M4", {{"tanpura", 0, 0.3}}, 4},
        {"sitar_M4", {{"sitar", 0, 0.3}}, 4},
        {"guitar_chord_6_voices_M4", chord, 4},
        // 2x: the modes below 43 kHz, every one below the internal Nyquist frequency, as a
        // run at that rate keeps them (the contact stays free of aliasing).
        {"tanpura_M2", {{"tanpura", 0, 0.3}}, 2},
        {"sitar_M2", {{"sitar", 0, 0.3}}, 2},
        {"guitar_chord_6_voices_M2", chord, 2},
    };
    for (const auto& s : sets)
        for (const bool flight : {true, false})
            benchmark::RegisterBenchmark((std::string(s.label) + (flight ? "/engine" : "/step_every_mode")).c_str(),
                                         [voices = s.voices, flight, m = s.max_oversampling](benchmark::State& st) {
                                             render(st, voices, flight, m);
                                         })
                ->Unit(benchmark::kMillisecond)
                ->Repetitions(5)
                ->ReportAggregatesOnly(true)
                ->Iterations(1);
}

}  // namespace

int main(int argc, char** argv) {
    register_all();
    benchmark::Initialize(&argc, argv);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
