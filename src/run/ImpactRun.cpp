#include "ImpactRun.hpp"

#include <algorithm>
#include <chrono>
#include <optional>
#include <cmath>
#include <string>
#include <vector>

#include "AudioBand.hpp"
#include "AudioStreams.hpp"
#include "EnergyAudit.hpp"
#include "RunLoop.hpp"
#include "SnapshotTaps.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/SubnormalFlush.hpp"
#include "fretbuzz/numerics/Kernels.hpp"
#include "fretbuzz/scheme/BridgeForce.hpp"
#include "fretbuzz/scheme/FreeFlight.hpp"
#include "fretbuzz/scheme/NewtonImpact.hpp"

namespace fretbuzz {

namespace {

// An exact point's impulse is reported at its nearest grid point (as a plucker's is).
std::vector<std::size_t> reported_points(const Case& c, const Plan& plan) {
    std::vector<std::size_t> index(plan.screened_points());
    const std::size_t n = plan.mode_count();
    for (std::size_t i = 0; i < n; ++i) index[i] = i;
    for (std::size_t p = 0; p < plan.point_contact().size(); ++p) {
        const double nearest = std::round(c.point_obstacles[p].x_m / c.grid_step()) - 1.0;
        index[n + p] = static_cast<std::size_t>(std::clamp(nearest, 0.0, static_cast<double>(n - 1)));
    }
    return index;
}

}  // namespace

RunSummary run_impact(const Case& c, std::span<RunObserver* const> observers, const RunOptions& options) {
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    auto last_progress = start;
    const SubnormalFlush flushed;
    const Plan plan(c, 1.0 / c.run.sample_rate_hz, options.plan);
    NewtonImpact string(plan, plan.oriented(c.initial_displacement), plan.oriented(c.initial_velocity));
    const std::vector<std::size_t> reported = reported_points(c, plan);

    RunLayout layout = layout_of(c);
    // Signals are linear in q: mirroring their coefficients mirrors them back.
    std::vector<std::vector<double>> shapes;
    for (double x : c.observation_points_m) shapes.push_back(plan.oriented(plan.basis().mode_shapes_at(x)));
    const std::vector<double> bridge = plan.oriented(bridge_force_coefficients(c));

    RunSummary summary = summary_of(c, plan, layout);
    summary.gestures = c.forces.size();
    summary.screened = plan.options().screen_contacts;
    summary.screening = summary.screened ? "on (impact law: points woken by the speed bound, free flight between contacts)"
                                         : "off (asked for)";

    for (RunObserver* o : observers) o->begin(layout);
    SnapshotTaps snapshots(c, plan, observers);
    AudioStreams audio(observers, c.run.sample_rate_hz, shapes.size(), 1);
    // Free flight over whole output intervals between contacts, as the penalty's run flies: the
    // modes below 0.6 x the audio rate (the sound's; the resampler removes the others) step one by
    // one, or with the closed-form sound (AudioBand) only the few a look at a point needs; the
    // others jump in closed form.
    std::optional<FreeFlight> flight;
    std::optional<AudioBand> band;
    std::size_t head = 0, check_head = 0;
    if (options.free_flight && plan.options().screen_contacts && layout.output_stride > 1) {
        const double band_hz = audio.empty() ? 0.0 : 0.6 * audio.lowest_rate_hz();
        while (head < c.mode_count() && c.modes.frequency_hz[head] < band_hz) ++head;
        check_head = std::min(kMinimumFlightModes, c.mode_count());
        head = std::max(head, check_head);
        flight.emplace(plan.propagator(), layout.output_stride);
        if (options.closed_form_audio && !audio.empty() &&
            AudioBand::applies(audio, plan.propagator(), head, layout.output_stride))
            band.emplace(audio, plan.propagator(), head, shapes, layout.output_stride);
    }
    const bool velocity = audio.wants_velocity();
    std::vector<double> u(shapes.size()), sound(shapes.size()), v(velocity ? shapes.size() : 0);
    std::vector<double> flown_rows;
    std::vector<std::pair<std::size_t, double>> forces;
    EnergyAudit audit;
    long n = 0, flown_steps = 0;
    const auto hear = [&] {  // the step's frame: u^n and (u^n - u^{n-1}) / dt at the points
        for (std::size_t p = 0; p < shapes.size(); ++p) sound[p] = string.displacement(shapes[p]);
        for (std::size_t p = 0; p < v.size(); ++p)
            v[p] = n > 0 ? kernels::dot(shapes[p].data(), string.modal_difference().data(), c.mode_count()) / layout.dt
                         : 0.0;
        audio.frame(sound, v);
    };
    const auto report_output = [&] {
        const double h = string.energy(), dissipated = string.dissipated();
        if (!std::isfinite(h) || !std::isfinite(dissipated))
            throw SolverError("the impact law's run produced a non-finite energy at t = " + std::to_string(string.time()) +
                              " s (step " + std::to_string(n) + ")");
        audit.record(h, dissipated, string.work());
        audit.write_to(summary);
        if (n % layout.output_stride != 0) return;
        const double t = string.time();
        for (std::size_t p = 0; p < shapes.size(); ++p) u[p] = string.displacement(shapes[p]);
        for (RunObserver* o : observers) o->observation(t, u);
        const double force = string.displacement(bridge);
        for (RunObserver* o : observers) o->bridge_force(t, force);
        for (RunObserver* o : observers) o->energy((static_cast<double>(n) - 0.5) * layout.dt, h, 0.0, dissipated);
    };
    const auto fly = [&] {  // the steps flown (0: none), their sound handed on
        const std::span<const double> q = string.modal_displacement(), d = string.modal_difference();
        const bool in_band = band && band->in_band();
        if (band && !in_band) band->flight_start(q, d);  // the band makes the flight's frames
        const std::span<const std::vector<double>> probes =
            audio.empty() || band ? std::span<const std::vector<double>>() : std::span<const std::vector<double>>(shapes);
        const long flown = string.free_flight(*flight, in_band ? check_head : head, probes, flown_rows);
        if (flown == 0) return flown;
        const bool complete = flown == layout.output_stride;
        const long end = string.step_index();
        if (in_band && complete) {
            band->flown(end, true, q, d);
        } else if (in_band) {
            band->resume(end, q, d);  // cut short: contact may come, the per-step sound resumes
        } else if (band) {
            band->flight_frames(flown);
            band->flown(end, complete, q, d);
        } else {
            for (long m = 0; m < flown && !audio.empty(); ++m) {
                const auto row = flown_rows.begin() + m * static_cast<long>(shapes.size());
                for (std::size_t p = 0; p < v.size(); ++p) v[p] = (row[static_cast<long>(p)] - sound[p]) / layout.dt;
                std::copy_n(row, shapes.size(), sound.begin());
                audio.frame(sound, v);
            }
        }
        return flown;
    };
    for (std::size_t p = 0; p < shapes.size(); ++p) u[p] = string.displacement(shapes[p]);
    for (RunObserver* o : observers) o->observation(0.0, u);
    for (RunObserver* o : observers) o->bridge_force(0.0, string.displacement(bridge));
    if (!audio.empty()) hear();
    snapshots.report(n, 0.0, string.modal_displacement());
    while (n < layout.steps) {
        throw_if_stopped();
        // A flight never jumps over a snapshot: it would miss the shape.
        if (flight && n > 1 && n % layout.output_stride == 0 && n + layout.output_stride <= layout.steps &&
            !snapshots.due_within(n, layout.output_stride)) {
            if (const long flown = fly(); flown > 0) {
                n = string.step_index();
                flown_steps += flown;
                snapshots.report(n, string.time(), string.modal_displacement());
                report_output();
                continue;
            }
        }
        if (band) band->resume(n, string.modal_displacement(), string.modal_difference());
        string.step();
        ++n;
        if (band) band->stepped(n);
        if (string.touched_obstacle()) {
            if (summary.first_contact_s < 0.0) summary.first_contact_s = string.time();
            summary.last_contact_s = string.time();
            forces.clear();
            for (const auto& [i, f] : string.forces()) forces.emplace_back(reported[i], plan.oriented(f));
            for (RunObserver* o : observers) o->contacts(string.time(), forces);
        }
        if (!audio.empty()) hear();
        if (!snapshots.empty()) snapshots.report(n, string.time(), string.modal_displacement());
        if (n == 1 || n % layout.output_stride == 0 || n == layout.steps) report_output();
        if ((n & 0xfff) == 0 && options.progress) {
            const auto now = Clock::now();
            if (now - last_progress >= std::chrono::milliseconds(500)) {
                last_progress = now;
                const double elapsed = std::chrono::duration<double>(now - start).count();
                const double fraction = static_cast<double>(n) / static_cast<double>(layout.steps);
                options.progress({fraction, string.time(), elapsed, elapsed * (1.0 - fraction) / fraction});
            }
        }
    }
    // The last segment ends at the run's end, as a single stream would.
    if (band) band->resume(n, string.modal_displacement(), string.modal_difference());
    summary.free_flight_fraction =
        layout.steps > 0 ? static_cast<double>(flown_steps) / static_cast<double>(layout.steps) : 0.0;
    if (!audio.empty()) audio.finish(summary.duration_s);
    summary.contact_steps = string.contact_steps();
    summary.impact_loss_j = string.impact_loss();
    summary.mean_points_solved =
        layout.steps > 0 ? static_cast<double>(string.points_checked()) / static_cast<double>(layout.steps) : 0.0;
    summary.subnormal_coordinates = 0;
    summary.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    summary.steps_per_second = summary.wall_seconds > 0.0 ? static_cast<double>(layout.steps) / summary.wall_seconds : 0.0;
    for (RunObserver* o : observers) o->finish(summary);
    throw_if_stopped();
    return summary;
}

}  // namespace fretbuzz
