// The set-up bench's speed and the convergence of its verdicts.
//
//   build/bench/fretbuzz_bench_setup [--repetitions N] [--jobs N] [--instrument NAME]
//       times, medians of N (default 3) each, on `--jobs` threads (default: every core):
//       - map: the whole map of `fretbuzz setup NAME` (every string, every fret, soft, medium
//         and hard, each note's ensemble, a WAV per note written to a scratch folder);
//       - what-if: one string (the first) after a what-if (the truss rod 0.1 mm looser), one
//         attack (medium), and when its notes come in (the first, the median gap, the last);
//       - the case-based study's load (bass-neck: a 2 mm pop, one pluck per note, 4 MHz, 0.5 s)
//         on one thread, for the side-by-side with the earlier `fretbuzz setup bass-neck`;
//       - a calibration from a 40-note report (`fretbuzz setup NAME --calibrate`): frets 0-9
//         of every string, each heard as the bench hears it at 1.3 x the medium pluck (the
//         report is made before the clock starts).
//   build/bench/fretbuzz_bench_setup --calibration [--instrument NAME] [--repetitions N]
//       the calibration's row alone.
//   build/bench/fretbuzz_bench_setup --convergence [--instrument NAME] [--attacks medium,hard]
//       the map at several sampling rates and durations against the finest (4 MHz, 0.5 s):
//       how many notes change their verdict (clean, marginal, buzzes), the mean change of the
//       share of plucks that buzz, of clean_up_to (relative) and of the median level. Prints
//       Markdown tables.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <string>
#include <vector>

#include "fretbuzz/input/InstrumentFile.hpp"
#include "fretbuzz/setup/BuzzMap.hpp"
#include "fretbuzz/setup/Calibration.hpp"
#include "fretbuzz/setup/StringNeck.hpp"
#include "fretbuzz/setup/WhatIf.hpp"

namespace {

using namespace fretbuzz;
using Clock = std::chrono::steady_clock;

double cpu_seconds() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
           1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Timing {
    double wall = 0.0, cpu = 0.0;
    BuzzMapResult map;
    std::vector<double> arrivals;  // s after the start, per verdict
};

Timing timed(const Instrument& instrument, MapRequest request) {
    Timing t;
    std::mutex mutex;
    const auto start = Clock::now();
    request.on_note = [&](const NoteVerdict&, std::size_t, std::size_t) {
        std::lock_guard lock(mutex);
        t.arrivals.push_back(std::chrono::duration<double>(Clock::now() - start).count());
    };
    const double cpu = cpu_seconds();
    t.map = play_map(instrument, request);
    t.wall = std::chrono::duration<double>(Clock::now() - start).count();
    t.cpu = cpu_seconds() - cpu;
    return t;
}

void report(const char* what, const std::vector<Timing>& runs) {
    std::vector<double> wall, cpu;
    for (const Timing& t : runs) {
        wall.push_back(t.wall);
        cpu.push_back(t.cpu);
    }
    const BuzzMapResult& m = runs.front().map;
    std::printf("%-58s wall %7.2f s (median of %zu), CPU %7.2f s, %zu notes, %zu plucks simulated, %zu clear, %u threads\n",
                what, median(wall), runs.size(), median(cpu), m.notes.size(), m.plucks_simulated, m.plucks_clear, m.jobs);
}

// A calibration from a 40-note report (its own row: `--calibration` times it alone).
int calibration_speed(const Instrument& instrument, int repetitions, unsigned jobs) {
    // The player's report: 40 notes, heard as the bench hears them at 1.3 x the medium pluck.
    MapRequest heard;
    for (std::size_t s = 0; s < instrument.strings.size() && heard.notes.size() < 40; ++s)
        for (std::size_t fret = 0; fret < 10 && heard.notes.size() < 40; ++fret) heard.notes.push_back({s, fret});
    heard.attacks = parse_attacks("medium", instrument.attack);
    heard.attacks.front().size *= 1.3;
    heard.clean_up_to = false;
    heard.jobs = jobs;
    std::string text = "string,fret,heard,strength\n";
    for (const NoteVerdict& v : play_map(instrument, heard).notes)
        text += instrument.strings[v.string].name + "," + std::to_string(v.fret) + "," +
                (v.verdict == "clean" ? "clean" : "buzz") + ",medium\n";
    const std::vector<HeardNote> report = parse_player_report(text, "bench-report.csv", instrument);
    std::vector<double> calibration_wall, calibration_cpu;
    double found = 0.0;
    for (int r = 0; r < repetitions; ++r) {
        CalibrationRequest request;
        request.jobs = jobs;
        const auto start = Clock::now();
        const double cpu = cpu_seconds();
        found = calibrate_attack(instrument, report, request).attack_scale;
        calibration_cpu.push_back(cpu_seconds() - cpu);
        calibration_wall.push_back(std::chrono::duration<double>(Clock::now() - start).count());
    }
    std::printf("%-58s wall %7.2f s (median of %zu), CPU %7.2f s, %zu notes, scale found %.3f (heard at 1.3)\n",
                "calibration from a 40-note report", median(calibration_wall), calibration_wall.size(),
                median(calibration_cpu), report.size(), found);
    return 0;
}

int speed(const std::string& name, int repetitions, unsigned jobs) {
    const Instrument instrument = load_instrument(name);
    const std::filesystem::path scratch = std::filesystem::temp_directory_path() / "fretbuzz-bench-setup-wavs";
    std::filesystem::create_directories(scratch);
    std::vector<Timing> maps, whatifs, studies;
    SetupChange looser;
    looser.relief_m = 0.1e-3 + StringNeck(instrument, 0).relief_gap(relief_fret(instrument));
    const Instrument changed = apply_change(instrument, looser);
    Instrument study = load_instrument("bass-neck");
    study.attack.ensemble = 1;
    for (int r = 0; r < repetitions; ++r) {
        MapRequest map;
        map.attacks = parse_attacks("soft,medium,hard", instrument.attack);
        map.jobs = jobs;
        map.audio_dir = scratch;
        maps.push_back(timed(instrument, map));
        MapRequest one;
        one.attacks = parse_attacks("medium", instrument.attack);
        one.strings = {0};
        one.jobs = jobs;
        whatifs.push_back(timed(changed, one));
        MapRequest pop;
        pop.attacks = parse_attacks("pop", study.attack);
        pop.jobs = 1;
        pop.frets = {};
        for (std::size_t k = 0; k < 20; ++k) pop.frets.push_back(k);  // the 20 notes the study played
        studies.push_back(timed(study, pop));
    }
    std::filesystem::remove_all(scratch);
    std::printf("fretbuzz_bench_setup: %s, %d repetitions\n", name.c_str(), repetitions);
    report(("map of " + name + " (soft, medium, hard; WAVs)").c_str(), maps);
    report(("what-if: relief +0.1 mm, string " + instrument.strings[0].name + ", medium").c_str(), whatifs);
    const std::vector<double>& a = whatifs.front().arrivals;
    std::vector<double> gaps;
    for (std::size_t k = 1; k < a.size(); ++k) gaps.push_back(a[k] - a[k - 1]);
    if (!a.empty())
        std::printf("  its notes come in: the first after %.2f s, then every %.2f s (median), the last after %.2f s\n",
                    a.front(), gaps.empty() ? 0.0 : median(gaps), a.back());
    report("bass-neck as the case-based study (pop, 1 pluck, 4 MHz, 0.5 s)", studies);
    return calibration_speed(instrument, repetitions, jobs);
}

struct Setting {
    double fs, duration, grid_step = 1e-3;
};

int convergence(const std::string& name, const std::string& attacks, unsigned jobs) {
    const Instrument base = load_instrument(name);
    const std::vector<Setting> settings = {{4e6, 0.5}, {2e6, 0.5}, {1e6, 0.5}, {5e5, 0.5}, {4e6, 0.3},
                                           {4e6, 0.2}, {4e6, 0.1}, {1e6, 0.3}, {5e5, 0.3}, {1e6, 0.3, 2e-3}};
    std::vector<BuzzMapResult> maps;
    std::vector<double> walls;
    for (const Setting& s : settings) {
        Instrument inst = base;
        inst.bench.sample_rate_hz = s.fs;
        inst.bench.duration_s = s.duration;
        inst.bench.grid_step_m = s.grid_step;
        MapRequest request;
        request.attacks = parse_attacks(attacks, inst.attack);
        request.jobs = jobs;
        const auto start = Clock::now();
        maps.push_back(play_map(inst, request));
        walls.push_back(std::chrono::duration<double>(Clock::now() - start).count());
        std::fprintf(stderr, "fs %g, %g s: %.1f s\n", s.fs, s.duration, walls.back());
    }
    const BuzzMapResult& ref = maps.front();
    std::printf("\n%s, %s: each map against the first (4 MHz, 0.5 s); %zu notes\n\n", name.c_str(), attacks.c_str(),
                ref.notes.size());
    std::printf("| fs | duration | grid step | verdicts changed (clean, marginal, buzzes) | mean change of buzz_fraction | "
                "median change of clean_up_to | mean change of buzz_dB (notes with a level in both) | buzzing / marginal | "
                "wall (s) |\n|---|---|---|---|---|---|---|---|---|\n");
    for (std::size_t k = 0; k < maps.size(); ++k) {
        std::size_t flips = 0, both = 0, buzzing = 0, marginal = 0;
        double dfraction = 0.0, ddb = 0.0;
        std::vector<double> dup;
        for (std::size_t i = 0; i < ref.notes.size(); ++i) {
            const NoteVerdict &a = maps[k].notes[i], &b = ref.notes[i];
            flips += a.verdict != b.verdict;
            buzzing += a.verdict == "buzzes";
            marginal += a.verdict == "marginal";
            dfraction += std::abs(a.buzz_fraction - b.buzz_fraction);
            if (std::isfinite(a.clean_up_to) && std::isfinite(b.clean_up_to) && b.clean_up_to > 0.0)
                dup.push_back(std::abs(a.clean_up_to / b.clean_up_to - 1.0));
            if (std::isfinite(a.buzz_db) && std::isfinite(b.buzz_db)) {
                ++both;
                ddb += std::abs(a.buzz_db - b.buzz_db);
            }
        }
        const double n = static_cast<double>(ref.notes.size());
        std::printf("| %g MHz | %g s | %g mm | %zu | %.3f | %.1f %% | %.2f dB (%zu) | %zu / %zu | %.1f |\n",
                    settings[k].fs / 1e6, settings[k].duration, settings[k].grid_step * 1e3, flips, dfraction / n,
                    dup.empty() ? 0.0 : 100.0 * median(dup), both ? ddb / static_cast<double>(both) : 0.0, both, buzzing,
                    marginal, walls[k]);
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    std::string instrument = "jazz-bass", attacks = "medium,hard";
    int repetitions = 3;
    unsigned jobs = 0;
    bool study = false, calibration_only = false;
    for (int k = 1; k < argc; ++k) {
        const std::string a = argv[k];
        const bool value = k + 1 < argc;
        if (a == "--convergence") {
            study = true;
        } else if (a == "--calibration") {
            calibration_only = true;
        } else if (a == "--instrument" && value) {
            instrument = argv[++k];
        } else if (a == "--attacks" && value) {
            attacks = argv[++k];
        } else if (a == "--repetitions" && value) {
            repetitions = std::max(1, std::atoi(argv[++k]));
        } else if (a == "--jobs" && value) {
            jobs = static_cast<unsigned>(std::max(1, std::atoi(argv[++k])));
        } else {
            std::fprintf(stderr, "usage: %s [--convergence | --calibration] [--instrument NAME] [--attacks LIST] [--repetitions N] "
                                 "[--jobs N]\n", argv[0]);
            return 2;
        }
    }
    try {
        if (calibration_only) return calibration_speed(load_instrument(instrument), repetitions, jobs);
        return study ? convergence(instrument, attacks, jobs) : speed(instrument, repetitions, jobs);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "fretbuzz_bench_setup: %s\n", e.what());
        return 1;
    }
}
