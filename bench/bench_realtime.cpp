// fretbuzz_bench_realtime: how much faster than real time does the real-time engine run, and
// how long is its worst block? Each benchmark renders one second of audio at 48 kHz in blocks
// of 256 samples, struck at the start of every iteration, one thread; times are the thread's
// CPU time (the machine is shared: wall time would count other processes). Side by side:
// the engine as shipped (free flight between contacts) and the same engine stepping every
// mode every step (the straightforward path). Fretted notes are played with the engine's
// finger (one engine per string, the finger pressed behind the fret before every strike);
// beside them, the former stand-in: an engine per fret on the string stopped at that fret
// (StoppedString, no finger), the cost of the same notes without the finger's solve.
// Counters (each repetition plays one second, 187 blocks; the median row is the median of the
// 5 repetitions' figures, which steadies the worst block, a single block of each):
//   x_realtime       audio seconds per CPU second
//   worst_block_pct  the longest single 256-sample block (CPU time), in % of its 5.33 ms
//   p99_block_pct    the 99th percentile of the blocks' times (the third longest of 187)
//   median_block_pct the median block
//   worst_block_contact_steps  internal steps of the longest block with a contact force (of
//                    M x 256): the longest blocks are those where the string buzzes at most steps
#include <benchmark/benchmark.h>

#include <algorithm>
#include <ctime>
#include <memory>
#include <vector>

#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/StoppedString.hpp"
#include "fretbuzz/input/StringsCaseFile.hpp"
#include "fretbuzz/realtime/BridgeEngine.hpp"
#include "fretbuzz/realtime/Engine.hpp"

namespace {

using namespace fretbuzz;

constexpr double kRate = 48000.0;
constexpr std::size_t kBlock = 256;

struct Voice {
    const char* name;
    int fret;
    double pluck;  // fraction of the sounding length
};

enum class Fretting { finger, stopped_string };

// CPU time of this thread: on a shared machine, wall time also counts other processes' turns.
double thread_seconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

std::unique_ptr<Engine> make_voice(const Voice& v, bool free_flight, int max_oversampling, Fretting fretting) {
    const Case open = load_case(v.name);
    EngineOptions o;
    o.host_rate_hz = kRate;
    o.free_flight = free_flight;
    o.max_oversampling = max_oversampling;
    if (v.fret == 0 || fretting == Fretting::finger) return std::make_unique<Engine>(open, o);
    return std::make_unique<Engine>(stopped_string(open, open.fret_positions_m.at(static_cast<std::size_t>(v.fret) - 1),
                                                   open.mode_count()),
                                    o);
}

// Plays one second per iteration in blocks of kBlock: start() strikes the voices, process(block)
// renders a block, contact_steps() counts the steps with a contact force so far.
template <class Start, class Process, class ContactSteps>
void time_blocks(benchmark::State& state, Start&& start, Process&& process, ContactSteps&& contact_steps) {
    std::vector<float> block(kBlock);
    const long blocks = static_cast<long>(kRate) / static_cast<long>(kBlock);
    std::vector<double> times;  // every block's CPU time (s), this repetition
    times.reserve(static_cast<std::size_t>(blocks));
    double worst = 0.0;
    long worst_contact_steps = 0;
    for (auto _ : state) {
        start();
        for (long b = 0; b < blocks; ++b) {
            const long before = contact_steps();
            const double t0 = thread_seconds();
            process(block);
            const double t = thread_seconds() - t0;
            times.push_back(t);
            if (t > worst) {
                worst = t;
                worst_contact_steps = contact_steps() - before;
            }
            benchmark::DoNotOptimize(block.data());
        }
    }
    const double audio_seconds = static_cast<double>(blocks * static_cast<long>(kBlock)) / kRate;
    const double block_seconds = static_cast<double>(kBlock) / kRate;
    // The q-quantile of this repetition's block times, in % of a block's duration.
    const auto quantile_pct = [&times, block_seconds](double q) {
        const auto at = times.begin() + static_cast<std::ptrdiff_t>(q * static_cast<double>(times.size() - 1));
        std::nth_element(times.begin(), at, times.end());
        return 100.0 * *at / block_seconds;
    };
    state.counters["x_realtime"] =
        benchmark::Counter(audio_seconds, benchmark::Counter::kIsIterationInvariantRate);
    state.counters["worst_block_pct"] = 100.0 * worst / block_seconds;
    state.counters["p99_block_pct"] = quantile_pct(0.99);
    state.counters["median_block_pct"] = quantile_pct(0.5);
    state.counters["worst_block_contact_steps"] = static_cast<double>(worst_contact_steps);
}

void render(benchmark::State& state, std::vector<Voice> voices, bool free_flight, int max_oversampling,
            Fretting fretting) {
    std::vector<std::unique_ptr<Engine>> engines;
    for (const Voice& v : voices) engines.push_back(make_voice(v, free_flight, max_oversampling, fretting));
    const auto start = [&] {
        for (std::size_t i = 0; i < engines.size(); ++i) {
            Engine& e = *engines[i];
            const bool finger = fretting == Fretting::finger && voices[i].fret > 0;
            if (finger) e.finger_down(voices[i].fret);
            const double stop = finger ? e.fret_position_m(voices[i].fret) : 0.0;
            e.strike({stop + voices[i].pluck * (e.length_m() - stop), 1.0, 0.01, false});
        }
    };
    const auto process = [&](std::vector<float>& block) {
        for (auto& e : engines) e->process(block);
    };
    const auto contact_steps = [&] {
        long n = 0;
        for (auto& e : engines) n += e->statistics().contact_steps;
        return n;
    };
    time_blocks(state, start, process, contact_steps);
    state.counters["modes"] = static_cast<double>(engines.front()->mode_count());
    state.counters["oversampling"] = engines.front()->oversampling();
    state.counters["latency_samples"] = engines.front()->latency_samples();
}

// Strings on one bridge (BridgeEngine): the strings of a strings case, or some of them (with
// their participations), each struck or fretted as `notes` says (string, fret, pluck fraction).
struct BridgeNote {
    std::size_t string;
    int fret;
    double pluck;
};

StringsCase some_strings(const StringsCase& sc, const std::vector<std::size_t>& keep) {
    StringsCase out = sc;
    out.strings.clear();
    out.string_names.clear();
    for (std::size_t s : keep) {
        out.strings.push_back(sc.strings[s]);
        out.string_names.push_back(sc.string_names[s]);
    }
    for (std::size_t b = 0; b < sc.bridge.size(); ++b) {
        out.bridge[b].participation.clear();
        for (std::size_t s : keep) out.bridge[b].participation.push_back(sc.bridge[b].participation[s]);
    }
    return out;
}

void render_bridge(benchmark::State& state, const StringsCase& sc, const BridgeEngineOptions& o,
                   const std::vector<BridgeNote>& notes) {
    BridgeEngine voice(sc, o);
    const auto start = [&] {
        for (const BridgeNote& n : notes) {
            if (n.fret > 0) voice.finger_down(n.string, n.fret);
            const double stop = voice.fret_position_m(n.string, n.fret);
            voice.strike(n.string, {stop + n.pluck * (voice.length_m(n.string) - stop), 1.0, 0.01, false});
        }
    };
    const auto process = [&](std::vector<float>& block) { voice.process(block); };
    const auto contact_steps = [&] {
        long n = 0;
        for (std::size_t s = 0; s < voice.string_count(); ++s) n += voice.assembly().string(s).record().stats.contact_steps;
        return n;
    };
    time_blocks(state, start, process, contact_steps);
    std::size_t modes = 0;
    for (std::size_t s = 0; s < voice.string_count(); ++s) modes += voice.mode_count(s);
    state.counters["strings"] = static_cast<double>(voice.string_count());
    state.counters["modes"] = static_cast<double>(modes);
    state.counters["oversampling"] = voice.oversampling();
    state.counters["latency_samples"] = voice.latency_samples();
}

void register_bridges() {
    const StringsCase sitar = parse_strings_case(*read_strings_case_text("sitar-taraf"));
    const StringsCase guitar = parse_strings_case(*read_strings_case_text("guitar-chord"));
    std::vector<std::size_t> all(sitar.strings.size()), eleven(12), taraf;
    for (std::size_t s = 0; s < all.size(); ++s) all[s] = s;
    for (std::size_t s = 0; s < eleven.size(); ++s) eleven[s] = s;  // the main string and 11 taraf
    for (std::size_t s = 1; s < all.size(); ++s) taraf.push_back(s);
    const std::vector<BridgeNote> main = {{0, 0, 0.72}};  // 0.25 m from the bridge end, as the case plucks it
    // An E major chord (A and D at fret 2, G at fret 1), every string struck.
    const std::vector<BridgeNote> chord = {{0, 0, 0.8}, {1, 2, 0.8}, {2, 2, 0.8}, {3, 1, 0.8}, {4, 0, 0.8}, {5, 0, 0.8}};
    const std::vector<BridgeNote> open = {{0, 0, 0.8}, {1, 0, 0.8}, {2, 0, 0.8}, {3, 0, 0.8}, {4, 0, 0.8}, {5, 0, 0.8}};
    const auto with = [](int max_oversampling, std::size_t max_free_modes) {
        BridgeEngineOptions o;
        o.engine.host_rate_hz = kRate;
        o.engine.max_oversampling = max_oversampling;
        o.max_free_modes = max_free_modes;
        return o;
    };
    BridgeEngineOptions at_8x = with(8, 0);
    at_8x.engine.oversampling = 8;  // the taraf strings alone would choose 1x: the sitar's rate
    const struct {
        const char* label;
        StringsCase sc;
        BridgeEngineOptions options;
        std::vector<BridgeNote> notes;
    } sets[] = {
        // Where the time goes: the whole sitar, then its main string alone on the bridge, its
        // taraf strings alone (one struck: every string is stepped at every step anyway).
        {"bridge_sitar_taraf13", sitar, with(8, 0), main},
        {"bridge_sitar_taraf11", some_strings(sitar, eleven), with(8, 0), main},
        {"bridge_sitar_main_only", some_strings(sitar, {0}), with(8, 0), main},
        {"bridge_taraf13_only", some_strings(sitar, taraf), at_8x, {{0, 0, 0.5}}},
        {"bridge_sitar_taraf13_M4", sitar, with(4, 0), main},
        {"bridge_sitar_taraf13_M2", sitar, with(2, 0), main},
        // Each taraf string cut to 20 modes (from 40, all below the host band).
        {"bridge_sitar_taraf13_taraf20modes", sitar, with(8, 20), main},
        {"bridge_guitar_chord", guitar, with(8, 0), chord},
        {"bridge_guitar_chord_M4", guitar, with(4, 0), chord},
        // The same strings struck open (no finger down): what the three fingers' pads cost.
        {"bridge_guitar_open", guitar, with(8, 0), open},
        // One open string alone on the bridge (the low E).
        {"bridge_guitar_E2_only", some_strings(guitar, {0}), with(8, 0), {{0, 0, 0.8}}},
    };
    for (const auto& s : sets)
        benchmark::RegisterBenchmark((std::string(s.label) + "/engine").c_str(),
                                     [sc = s.sc, o = s.options, notes = s.notes](benchmark::State& st) {
                                         render_bridge(st, sc, o, notes);
                                     })
            ->Unit(benchmark::kMillisecond)
            ->Repetitions(5)
            ->ReportAggregatesOnly(true)
            ->Iterations(1);
}

void register_all() {
    // Six strings of the guitar-neck case (its low E, with frets), fingered as an open C chord.
    const std::vector<Voice> chord = {{"guitar-neck", 0, 0.8}, {"guitar-neck", 3, 0.8}, {"guitar-neck", 2, 0.8},
                                      {"guitar-neck", 0, 0.8}, {"guitar-neck", 1, 0.8}, {"guitar-neck", 0, 0.8}};
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
        {"bass_fret5_M4", {{"bass-pluck", 5, 0.8}}, 4},
        {"guitar_chord_6_voices", chord, 8},
        {"tanpura_M4", {{"tanpura", 0, 0.3}}, 4},
        {"sitar_M4", {{"sitar", 0, 0.3}}, 4},
        {"guitar_chord_6_voices_M4", chord, 4},
        // 2x: the modes below 43 kHz, every one below the internal Nyquist frequency, as a
        // run at that rate keeps them (the contact stays free of aliasing).
        {"tanpura_M2", {{"tanpura", 0, 0.3}}, 2},
        {"sitar_M2", {{"sitar", 0, 0.3}}, 2},
        {"guitar_chord_6_voices_M2", chord, 2},
        // 1x: the host rate itself and the modes below its Nyquist frequency (100 and 137): what
        // a 48 kHz simulation keeps, fastest and farthest from the buzz at 8x (fretbuzz_rate_accuracy).
        {"tanpura_M1", {{"tanpura", 0, 0.3}}, 1},
        {"sitar_M1", {{"sitar", 0, 0.3}}, 1},
    };
    const auto add = [](const std::string& name, const std::vector<Voice>& voices, bool flight, int m, Fretting f) {
        benchmark::RegisterBenchmark(name.c_str(), [voices, flight, m, f](benchmark::State& st) {
            render(st, voices, flight, m, f);
        })
            ->Unit(benchmark::kMillisecond)
            ->Repetitions(5)
            ->ReportAggregatesOnly(true)
            ->Iterations(1);
    };
    for (const auto& s : sets) {
        const bool fretted = std::any_of(s.voices.begin(), s.voices.end(), [](const Voice& v) { return v.fret > 0; });
        for (const bool flight : {true, false})
            add(std::string(s.label) + (flight ? "/engine" : "/step_every_mode"), s.voices, flight, s.max_oversampling,
                Fretting::finger);
        if (fretted) add(std::string(s.label) + "/stopped_string", s.voices, true, s.max_oversampling, Fretting::stopped_string);
    }
}

}  // namespace

int main(int argc, char** argv) {
    register_all();
    register_bridges();
    benchmark::Initialize(&argc, argv);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
