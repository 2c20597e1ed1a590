#include "ImpactRun.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "AudioStreams.hpp"
#include "EnergyAudit.hpp"
#include "RunLoop.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/SubnormalFlush.hpp"
#include "fretbuzz/scheme/BridgeForce.hpp"
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
    summary.screened = plan.options().screen_contacts;
    summary.screening = summary.screened ? "on (impact law: points woken by the speed bound, no free flight)"
                                         : "off (asked for)";

    for (RunObserver* o : observers) o->begin(layout);
    AudioStreams audio(observers, c.run.sample_rate_hz, shapes.size(), 1);
    const bool velocity = audio.wants_velocity();
    std::vector<double> u(shapes.size()), v(velocity ? shapes.size() : 0), previous(shapes.size());
    std::vector<std::pair<std::size_t, double>> forces;
    EnergyAudit audit;
    long n = 0;
    const auto observe = [&] {
        for (std::size_t p = 0; p < shapes.size(); ++p) {
            previous[p] = u[p];
            u[p] = string.displacement(shapes[p]);
        }
    };
    const auto report_output = [&] {
        const double h = string.energy(), dissipated = string.dissipated();
        if (!std::isfinite(h) || !std::isfinite(dissipated))
            throw SolverError("the impact law's run produced a non-finite energy at t = " + std::to_string(string.time()) +
                              " s (step " + std::to_string(n) + ")");
        audit.record(h, dissipated);
        audit.write_to(summary);
        if (n % layout.output_stride != 0) return;
        const double t = string.time();
        for (RunObserver* o : observers) o->observation(t, u);
        const double force = string.displacement(bridge);
        for (RunObserver* o : observers) o->bridge_force(t, force);
        for (RunObserver* o : observers) o->energy((static_cast<double>(n) - 0.5) * layout.dt, h, 0.0, dissipated);
    };
    observe();
    for (RunObserver* o : observers) o->observation(0.0, u);
    for (RunObserver* o : observers) o->bridge_force(0.0, string.displacement(bridge));
    if (!audio.empty()) audio.frame(u, v);
    while (n < layout.steps) {
        throw_if_stopped();
        string.step();
        ++n;
        observe();
        if (string.touched_obstacle()) {
            if (summary.first_contact_s < 0.0) summary.first_contact_s = string.time();
            summary.last_contact_s = string.time();
            forces.clear();
            for (const auto& [i, f] : string.forces()) forces.emplace_back(reported[i], plan.oriented(f));
            for (RunObserver* o : observers) o->contacts(string.time(), forces);
        }
        if (!audio.empty()) {
            for (std::size_t p = 0; p < v.size(); ++p) v[p] = (u[p] - previous[p]) / layout.dt;
            audio.frame(u, v);
        }
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
