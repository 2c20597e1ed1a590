// fretbuzz_bench_stopped: the cost of a stopped string (input/StoppedString.hpp), i.e. of the
// held string's modes it takes its frequencies from (scheme/HeldString.hpp), per fret and for
// the 24 frets that the LV2 plugin prepares when it is instantiated (one voice per fret, the
// open string's full mode count). Times are the thread's CPU time (the machine is shared).
#include <benchmark/benchmark.h>

#include <ctime>
#include <string>

#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/StoppedString.hpp"

namespace {

using namespace fretbuzz;

constexpr int kFrets = 24;  // the plugin's frets 1..24

double thread_seconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

void one_fret(benchmark::State& state, const std::string& name) {
    const Case open = load_case(name);
    const double stop = fret_position(open.string.length_m, static_cast<int>(state.range(0)));
    for (auto _ : state) {
        const double start = thread_seconds();
        benchmark::DoNotOptimize(stopped_string(open, stop, open.mode_count()));
        state.SetIterationTime(thread_seconds() - start);
    }
    state.counters["modes"] = static_cast<double>(open.mode_count());
}

void every_fret(benchmark::State& state, const std::string& name) {
    const Case open = load_case(name);
    for (auto _ : state) {
        const double start = thread_seconds();
        for (int k = 1; k <= kFrets; ++k)
            benchmark::DoNotOptimize(stopped_string(open, fret_stop_m(open, k), open.mode_count()));
        state.SetIterationTime(thread_seconds() - start);
    }
    state.counters["modes"] = static_cast<double>(open.mode_count());
}

}  // namespace

BENCHMARK_CAPTURE(one_fret, bass_pluck, std::string("bass-pluck"))
    ->Arg(1)->Arg(12)->Arg(24)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(every_fret, bass_pluck, std::string("bass-pluck"))
    ->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(one_fret, guitar_point, std::string("guitar-point"))
    ->Arg(1)->Arg(12)->Arg(24)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(every_fret, guitar_point, std::string("guitar-point"))
    ->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(one_fret, sitar, std::string("sitar"))
    ->Arg(1)->Arg(12)->Arg(24)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(every_fret, sitar, std::string("sitar"))
    ->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(one_fret, tanpura, std::string("tanpura"))
    ->Arg(1)->Arg(12)->Arg(24)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(every_fret, tanpura, std::string("tanpura"))
    ->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(3);

BENCHMARK_MAIN();
