#include "fretbuzz/run/StringsRun.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>

#include "EnergyAudit.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/run/Resampler.hpp"
#include "fretbuzz/scheme/Assembly.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/SecondPolarisation.hpp"
#include "fretbuzz/SubnormalFlush.hpp"

namespace fretbuzz {

StringsSummary simulate_strings(const StringsCase& sc, StringsObserver& observer) {
    const SubnormalFlush flushed;  // for every step of the run, on whichever thread runs it
    const auto started = std::chrono::steady_clock::now();
    const double fs = sc.run.sample_rate_hz, dt = 1.0 / fs;
    const std::size_t S = sc.strings.size();
    std::vector<std::unique_ptr<Plan>> plans;
    std::vector<Assembly::OnBridge> on_bridge;
    std::vector<std::vector<double>> z0, v0;  // each string's initial state along z
    for (std::size_t s = 0; s < S; ++s) {
        const Case& c = sc.strings[s];
        plans.push_back(std::make_unique<Plan>(c, dt));
        // The bridge moves the strings' ends along z, the side the obstacles are on: a plan that
        // runs a string's mirror image (an obstacle above it) would turn the bridge over too.
        if (plans.back()->orientation() < 0.0)
            throw InputError("string " + sc.string_names[s] + ": an obstacle above the string is not supported on a bridge (put it below, as the built-in cases do)");
        z0.push_back(along_polarisation(c.initial_displacement, c, false));
        v0.push_back(along_polarisation(c.initial_velocity, c, false));
    }
    for (std::size_t s = 0; s < S; ++s) on_bridge.push_back({plans[s].get(), sc.strings[s].string, z0[s], v0[s]});
    Assembly assembly(on_bridge, sc.bridge);
    // A string with two polarisations: its y polarisation rests on an end the bridge does not
    // move (the bridge's modes move along z only); its energy is in the string's.
    for (std::size_t s = 0; s < S; ++s) {
        const Case& c = sc.strings[s];
        if (c.two_polarisations())
            assembly.string(s).add_second_polarisation(along_polarisation(c.initial_displacement, c, true),
                                                       along_polarisation(c.initial_velocity, c, true));
    }
    // Each string's pickup (along z): its first observation point, read by the step's own pass.
    std::vector<std::vector<double>> shapes;
    for (std::size_t s = 0; s < S; ++s) {
        const Case& c = sc.strings[s];
        const double x = c.observation_points_m.empty() ? 0.9 * c.string.length_m : c.observation_points_m.front();
        shapes.push_back(plans[s]->basis().mode_shapes_at(x));
        assembly.string(s).pickups().observe(shapes[s].data(), assembly.string(s).modes());
    }
    const auto pickup = [&](std::size_t s) {
        return assembly.string(s).pickups().observation(plans[s]->options().fused_step, assembly.string(s).modes());
    };

    StringsSummary summary;
    summary.output_rate_hz = sc.run.output_rate_hz.value_or(kStringsRowsPerSecond);
    summary.audio_rate_hz = sc.run.audio_rate_hz;
    const long steps = std::lround(sc.run.duration_s * fs);
    // In double, so that an output rate far below 1/duration gives one row (the first), not an overflow.
    const auto stride = static_cast<long>(std::clamp(std::round(fs / summary.output_rate_hz), 1.0, static_cast<double>(steps)));
    Resampler resampler(fs, summary.audio_rate_hz, S + 1);
    constexpr std::size_t kBlock = 4096;
    std::vector<double> frames, audio, row(S + 3);
    frames.reserve(kBlock * (S + 1));
    const auto flush = [&](bool last) {
        audio.clear();
        resampler.process(frames, audio, last);
        frames.clear();
        if (!audio.empty()) observer.audio(audio);
    };
    // The balance judged as a one-string run's is (EnergyAudit), from the energy after the first step.
    EnergyAudit audit;
    for (long n = 1; n <= steps; ++n) {
        assembly.step();
        frames.push_back(n == 1 ? 0.0 : assembly.bridge()->velocity());
        for (std::size_t s = 0; s < S; ++s) frames.push_back(pickup(s));
        if (frames.size() >= kBlock * (S + 1)) {
            flush(false);
            throw_if_stopped();
        }
        if (n % stride != 0 && n != 1) continue;
        const double t = static_cast<double>(n) * dt;
        if (!std::isfinite(assembly.energy() + assembly.dissipated() - assembly.work()))
            throw SolverError("strings on a bridge: the energy is not finite at t = " + std::to_string(t) + " s");
        audit.record(assembly.energy(), assembly.dissipated(), assembly.work());
        row[0] = t;
        for (std::size_t s = 0; s < S; ++s) row[1 + s] = assembly.string_energy(s);
        row[S + 1] = assembly.bridge()->energy();
        row[S + 2] = audit.relative_balance();
        observer.row(row);
    }
    flush(true);
    summary.steps = steps;
    summary.max_relative_energy_increase = audit.max_relative_energy_increase();
    summary.max_relative_balance_error = audit.max_relative_balance_error();
    summary.subnormal_coordinates = assembly.subnormal_coordinates();
    summary.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    return summary;
}

namespace {

// Keeps every row and frame (StringsRun).
class StringsRecorder : public StringsObserver {
public:
    StringsRecorder(StringsRun& run, std::size_t strings) : run_(run) {
        run_.energy.assign(strings, {});
        run_.pickup_audio.assign(strings, {});
    }
    void row(std::span<const double> values) override {
        const std::size_t S = run_.energy.size();
        run_.t.push_back(values[0]);
        for (std::size_t s = 0; s < S; ++s) run_.energy[s].push_back(values[1 + s]);
        run_.bridge_energy.push_back(values[S + 1]);
        run_.balance.push_back(values[S + 2]);
    }
    void audio(std::span<const double> frames) override {
        const std::size_t S = run_.pickup_audio.size();
        for (std::size_t k = 0; k + S < frames.size(); k += S + 1) {
            run_.bridge_audio.push_back(frames[k]);
            for (std::size_t s = 0; s < S; ++s) run_.pickup_audio[s].push_back(frames[k + 1 + s]);
        }
    }

private:
    StringsRun& run_;
};

}  // namespace

StringsRun simulate_strings(const StringsCase& sc) {
    StringsRun run;
    StringsRecorder recorder(run, sc.strings.size());
    static_cast<StringsSummary&>(run) = simulate_strings(sc, recorder);
    return run;
}

}  // namespace fretbuzz
