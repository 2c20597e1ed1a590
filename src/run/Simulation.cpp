#include "fretbuzz/run/Simulation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>

#include "fretbuzz/scheme/Stepper.hpp"

namespace fretbuzz {

long output_stride(const Case& c) {
    if (!c.run.output_rate_hz) return 1;
    return std::max(1L, std::lround(c.run.sample_rate_hz / *c.run.output_rate_hz));
}

namespace {

// Tracks the energy balance over the samples the run reports.
class EnergyAudit {
public:
    void record(double h, double dissipated, RunSummary& s) {
        if (!started_) {
            started_ = true;
            s.energy_initial_j = h;
            previous_ = h;
        }
        const double reference = s.energy_initial_j > 0.0 ? s.energy_initial_j : 1.0;
        s.max_relative_energy_increase = std::max(s.max_relative_energy_increase, (h - previous_) / reference);
        s.max_relative_balance_error =
            std::max(s.max_relative_balance_error, std::abs(h + dissipated - s.energy_initial_j) / reference);
        previous_ = h;
        s.energy_final_j = h;
        s.dissipated_j = dissipated;
    }

private:
    bool started_ = false;
    double previous_ = 0.0;
};

}  // namespace

RunSummary simulate(const Case& c, std::span<RunObserver* const> observers, const RunOptions& options) {
    c.validate();
    using clock = std::chrono::steady_clock;
    const auto start = clock::now();
    const double dt = 1.0 / c.run.sample_rate_hz;
    const Plan plan(c, dt, options.plan);

    RunLayout layout;
    layout.source = &c;
    layout.dt = dt;
    layout.steps = std::lround(c.run.duration_s * c.run.sample_rate_hz);
    layout.output_stride = output_stride(c);
    layout.output_rate_hz = c.run.sample_rate_hz / static_cast<double>(layout.output_stride);
    layout.observation_points_m = c.observation_points_m;

    std::vector<std::vector<double>> shapes;
    for (double x : c.observation_points_m) shapes.push_back(plan.basis().mode_shapes_at(x));
    std::vector<RunObserver*> per_step;
    bool velocity_wanted = false;
    struct SnapshotTap {
        RunObserver* observer;
        long stride;
        long last_step;  // no snapshots after this step
    };
    std::vector<SnapshotTap> snapshot_taps;
    for (RunObserver* o : observers) {
        o->begin(layout);
        if (o->wants_every_step()) per_step.push_back(o);
        velocity_wanted = velocity_wanted || o->wants_velocity();
        if (const double rate = o->snapshot_rate_hz(); rate > 0.0) {
            const double until = std::min(o->snapshot_until_s(), c.run.duration_s);
            snapshot_taps.push_back({o, std::max(1L, std::lround(c.run.sample_rate_hz / rate)),
                                     static_cast<long>(std::floor(until * c.run.sample_rate_hz))});
        }
    }
    std::vector<double> grid_x(c.mode_count()), grid_u(c.mode_count());
    for (std::size_t i = 0; i < grid_x.size(); ++i) grid_x[i] = plan.basis().grid_point(i);

    RunSummary summary;
    summary.case_name = c.name;
    summary.sample_rate_hz = c.run.sample_rate_hz;
    summary.duration_s = static_cast<double>(layout.steps) / c.run.sample_rate_hz;
    summary.steps = layout.steps;
    summary.modes = c.mode_count();
    summary.output_rate_hz = layout.output_rate_hz;
    summary.lossless = plan.propagator().lossless();
    summary.screened = options.plan.screen_contacts;

    Stepper stepper(plan, c.initial_displacement, c.initial_velocity);
    std::vector<double> u(shapes.size());
    EnergyAudit audit;
    auto report_observation = [&]() {
        for (std::size_t p = 0; p < shapes.size(); ++p) u[p] = stepper.displacement(shapes[p]);
        for (RunObserver* o : observers) o->observation(stepper.time(), u);
    };
    std::vector<double> step_u(shapes.size()), step_v(velocity_wanted ? shapes.size() : 0);
    auto report_step = [&]() {
        for (std::size_t p = 0; p < shapes.size(); ++p) step_u[p] = stepper.displacement(shapes[p]);
        for (std::size_t p = 0; p < step_v.size(); ++p) step_v[p] = stepper.time() > 0.0 ? stepper.velocity(shapes[p]) : 0.0;
        for (RunObserver* o : per_step) o->every_step(step_u, step_v);
    };
    auto report_snapshots = [&](long n) {
        bool shaped = false;
        for (const SnapshotTap& tap : snapshot_taps) {
            if (n % tap.stride != 0 || n > tap.last_step) continue;
            if (!shaped) plan.basis().to_grid(stepper.modal_displacement(), grid_u);
            shaped = true;
            tap.observer->snapshot(stepper.time(), grid_x, grid_u);
        }
    };
    report_observation();
    if (!per_step.empty()) report_step();
    report_snapshots(0);

    // Free flight: at output boundaries, jump a whole output interval when nothing can touch.
    // Per-step observers then get the signal band-limited to the modes below their band.
    double band_hz = std::numeric_limits<double>::infinity();
    for (RunObserver* o : per_step) band_hz = std::min(band_hz, o->every_step_band_hz());
    const bool may_fly = options.free_flight && options.plan.screen_contacts && layout.output_stride > 1 && band_hz > 0.0;
    std::size_t head = 0;
    if (per_step.empty()) band_hz = 0.0;
    while (head < c.mode_count() && c.modes.frequency_hz[head] < band_hz) ++head;
    head = std::max(head, std::min<std::size_t>(48, c.mode_count()));  // enough for sharp checks
    std::optional<FreeFlight> flight;
    if (may_fly) flight.emplace(plan.propagator(), layout.output_stride);
    std::vector<double> flight_u, flight_v;
    auto no_snapshot_within = [&](long n, long steps) {
        for (const SnapshotTap& tap : snapshot_taps) {
            const long next = (n / tap.stride + 1) * tap.stride;
            if (next < n + steps && next <= tap.last_step) return false;
        }
        return true;
    };

    auto report_output = [&](long n) {
        const double h = stepper.energy();
        audit.record(h, stepper.dissipated(), summary);
        if (n % layout.output_stride != 0) return;
        report_observation();
        const double t_half = (static_cast<double>(n) - 0.5) * dt;
        for (RunObserver* o : observers) o->energy(t_half, h, stepper.contact_energy(), stepper.dissipated());
    };
    auto last_progress = start;
    auto report_progress = [&](long n) {
        const auto now = clock::now();
        if (now - last_progress < std::chrono::milliseconds(500)) return;
        last_progress = now;
        const double elapsed = std::chrono::duration<double>(now - start).count();
        const double fraction = static_cast<double>(n) / static_cast<double>(layout.steps);
        options.progress({fraction, stepper.time(), elapsed, elapsed * (1.0 - fraction) / fraction});
    };

    long n = 0;
    while (n < layout.steps) {
        const long stride = layout.output_stride;
        long flown = 0;
        if (flight && n > 1 && n % stride == 0 && n + stride <= layout.steps && no_snapshot_within(n, stride))
            flown = stepper.free_flight(*flight, head, shapes, flight_u, velocity_wanted ? &flight_v : nullptr);
        if (flown > 0) {
            const std::size_t width = shapes.size();
            for (long m = 0; m < flown; ++m) {
                const auto row = static_cast<std::size_t>(m) * width;
                const std::span<const double> row_u(flight_u.data() + row, width);
                const std::span<const double> row_v =
                    velocity_wanted ? std::span<const double>(flight_v.data() + row, width) : std::span<const double>();
                for (RunObserver* o : per_step) o->every_step(row_u, row_v);
            }
            n += flown;
            if (flown == stride) {
                report_snapshots(n);
                report_output(n);
            }
            if (options.progress) report_progress(n);
            continue;
        }
        stepper.step();
        ++n;
        if (!stepper.forces().empty()) {
            if (summary.first_contact_s < 0.0) summary.first_contact_s = stepper.time();
            summary.last_contact_s = stepper.time();
            for (RunObserver* o : observers) o->contacts(stepper.time(), stepper.forces());
        }
        if (!per_step.empty()) report_step();
        if (!snapshot_taps.empty()) report_snapshots(n);
        if (n % stride == 0 || n == 1) report_output(n);
        if (options.progress && (n & 0xfff) == 0) report_progress(n);
    }

    const StepStatistics& stats = stepper.statistics();
    summary.contact_steps = stats.contact_steps;
    summary.max_newton_iterations = stats.max_newton_iterations;
    summary.mean_points_solved = layout.steps > 0 ? stats.points_solved / static_cast<double>(layout.steps) : 0.0;
    summary.free_flight_fraction =
        layout.steps > 0 ? static_cast<double>(stats.free_flight_steps) / static_cast<double>(layout.steps) : 0.0;
    summary.wall_seconds = std::chrono::duration<double>(clock::now() - start).count();
    summary.steps_per_second = summary.wall_seconds > 0.0 ? static_cast<double>(layout.steps) / summary.wall_seconds : 0.0;
    for (RunObserver* o : observers) o->finish(summary);
    return summary;
}

}  // namespace fretbuzz
