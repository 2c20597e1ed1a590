#include "fretbuzz/run/StringsRun.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/run/Resampler.hpp"
#include "fretbuzz/scheme/Assembly.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/SecondPolarisation.hpp"
#include "fretbuzz/SubnormalFlush.hpp"

namespace fretbuzz {

StringsRun simulate_strings(const StringsCase& sc) {
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
    std::vector<std::vector<double>> rows;
    for (std::size_t s = 0; s < S; ++s) {
        const Case& c = sc.strings[s];
        const double x = c.observation_points_m.empty() ? 0.9 * c.string.length_m : c.observation_points_m.front();
        rows.push_back(plans[s]->basis().mode_shapes_at(x));
        assembly.string(s).pickups().observe(rows[s].data(), assembly.string(s).modes());
    }
    const auto pickup = [&](std::size_t s) {
        return assembly.string(s).pickups().observation(plans[s]->options().fused_step, assembly.string(s).modes());
    };

    StringsRun run;
    run.output_rate_hz = sc.run.output_rate_hz.value_or(kStringsRowsPerSecond);
    run.audio_rate_hz = sc.run.audio_rate_hz;
    run.energy.assign(S, {});
    run.pickup_audio.assign(S, {});
    const long steps = std::lround(sc.run.duration_s * fs);
    const long stride = std::max(1L, std::lround(fs / run.output_rate_hz));
    Resampler resampler(fs, run.audio_rate_hz, S + 1);
    constexpr std::size_t kBlock = 4096;
    std::vector<double> frames, audio;
    frames.reserve(kBlock * (S + 1));
    const auto flush = [&](bool last) {
        audio.clear();
        resampler.process(frames, audio, last);
        frames.clear();
        for (std::size_t k = 0; k + S < audio.size(); k += S + 1) {
            run.bridge_audio.push_back(audio[k]);
            for (std::size_t s = 0; s < S; ++s) run.pickup_audio[s].push_back(audio[k + 1 + s]);
        }
    };
    double first = 0.0, largest_work = 0.0;
    for (long n = 1; n <= steps; ++n) {
        assembly.step();
        frames.push_back(n == 1 ? 0.0 : assembly.bridge()->velocity());
        for (std::size_t s = 0; s < S; ++s) frames.push_back(pickup(s));
        if (frames.size() >= kBlock * (S + 1)) {
            flush(false);
            throw_if_stopped();
        }
        if (n == 1) first = assembly.energy();
        if (n % stride != 0 && n != 1) continue;
        largest_work = std::max(largest_work, std::abs(assembly.work()));
        run.t.push_back(static_cast<double>(n) * dt);
        for (std::size_t s = 0; s < S; ++s) run.energy[s].push_back(assembly.string_energy(s));
        run.bridge_energy.push_back(assembly.bridge()->energy());
        const double total = assembly.energy() + assembly.dissipated() - assembly.work();
        // Relative to the energy at the start or, for strings played from rest (pluckers, fingers),
        // to the largest work put in so far (as a one-string run's audit judges it).
        const double scale = std::max(first, largest_work);
        const double residual = scale > 0.0 ? (total - first) / scale : 0.0;
        if (!std::isfinite(total)) throw SolverError("strings on a bridge: the energy is not finite at t = " + std::to_string(static_cast<double>(n) * dt) + " s");
        run.balance.push_back(residual);
        run.worst_balance = std::max(run.worst_balance, std::abs(residual));
    }
    flush(true);
    run.steps = steps;
    run.subnormal_coordinates = assembly.subnormal_coordinates();
    run.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    return run;
}

}  // namespace fretbuzz
