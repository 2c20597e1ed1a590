#include "fretbuzz/scheme/Plan.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/scheme/SamplingCheck.hpp"

namespace fretbuzz {

namespace {
// A point the grid's own solve takes: on a grid point, one grid step wide.
bool has_grid_obstacle(const Case& c) {
    return std::any_of(c.obstacle_height_m.begin(), c.obstacle_height_m.end(), [](double g) { return std::isfinite(g); });
}

bool joins_grid(const Case& c, const PointObstacle& p, const PlanOptions& options) {
    // (Pluckers and fingers beside the points join their solve: each plucker as one more
    // unknown, the fingers through their pads' grid points; no number of them moves the points.)
    const double dx = c.grid_step();
    const double x = (std::round(p.x_m / dx)) * dx;
    return options.grid_points_on_grid && std::abs(p.x_m - x) <= 1e-12 * c.string.length_m &&
           std::abs(p.weight_m - dx) <= 1e-12 * dx;
}

// The step kernel for the modes' damping: without losses the step skips their terms.
kernels::StepKernel step_kernel_for(const ModalPropagator& propagator) {
    return propagator.lossless() ? kernels::step_lossless : kernels::step_lossy;
}
}  // namespace

Plan::Plan(const Case& c, double dt, PlanOptions options)
    : dt_(dt),
      orientation_(c.contact_orientation()),
      mu_(c.string.linear_density),
      energy_scale_(mu_ / (2.0 * dt_ * dt_)),
      loss_scale_(mu_ / (4.0 * dt_ * dt_)),
      basis_(c.string.length_m, c.mode_count(), options.measure_transform),
      propagator_(c.modes, dt),
      step_kernel_(step_kernel_for(propagator_)),
      contact_(c.contact.stiffness, c.contact.exponent, options.closed_form_contact),
      law_(c.contact.law),
      restitution_(c.contact.restitution),
      friction_(c.polarisation.friction, c.polarisation.friction_velocity),
      obstacle_(c.obstacle_height_m),
      fingers_(c.fingers),
      forces_(c.forces),
      plucks_(c.plucks),
      options_(options) {
    require_positive("time step dt (s)", dt);
    if (c.two_polarisations()) propagator_y_.emplace(c.y_modes(), dt);
    // Without contact the modal update is exact at any dt: nothing can alias.
    if (contact_possible(c)) warnings_ = require_sampling(c.modes, 1.0 / dt, c.run.allow_aliasing).warnings;
    // An obstacle above is solved as its mirror image below (u -> -u).
    for (double& g : obstacle_)
        if (std::isfinite(g)) g = oriented(g);
    place_points(c);
    for (std::size_t i = 0; i < obstacle_.size(); ++i)
        if (std::isfinite(obstacle_[i])) obstacle_points_.push_back(i);
    planned_obstacle_ = obstacle_;
    transform_threshold_ = options.transform_threshold != 0 ? options.transform_threshold
                                                            : default_transform_threshold(mode_count(), basis_.transform_flops());
}

void Plan::place_points(const Case& c) {
    // Points that all join the grid (see joins_grid) are solved as grid points. Otherwise every
    // point is solved by PointContact: an off-grid point's row is not orthogonal to a grid
    // point's, so their equations couple.
    const bool all_on_grid = std::all_of(c.point_obstacles.begin(), c.point_obstacles.end(),
                                         [&](const PointObstacle& p) { return joins_grid(c, p, options_); });
    std::vector<PointObstacle> points = c.point_obstacles;
    for (PointObstacle& p : points)
        p.height_m = oriented(p.height_m);
    if (!all_on_grid) {
        // Beside obstacle points on the grid (a fretboard's board under its frets) or a finger's
        // pad, the points' equations and the grid's are solved together: their couplings
        // phi(x_p) . S_i are kept.
        point_contact_ = PointContact(basis_, std::move(points), has_grid_obstacle(c) || !c.fingers.empty());
        return;
    }
    // Exact pluckers beside fingers are solved with their pads even with no point off the grid:
    // the solve's state needs room for the pads (a PointContact with no points).
    if (!c.plucks.empty() && !c.fingers.empty())
        point_contact_ = PointContact(basis_, {}, true);
    for (const PointObstacle& p : points) {
        const double index = std::clamp(std::round(p.x_m / basis_.grid_step()) - 1.0, 0.0, static_cast<double>(obstacle_.size() - 1));
        double& g = obstacle_[static_cast<std::size_t>(index)];
        g = std::max(g, p.height_m);
    }
}

void Plan::set_damping(std::span<const double> sigma_per_s) {
    propagator_.set_damping(sigma_per_s);
    step_kernel_ = step_kernel_for(propagator_);
}

void Plan::set_obstacle_offset(double offset) {
    point_contact_.set_offset(offset);
    for (std::size_t i : obstacle_points_)
        obstacle_[i] = std::min(planned_obstacle_[i] + offset, std::max(planned_obstacle_[i], 0.0));
}

void Plan::forces_to_modes(std::span<const std::pair<std::size_t, double>> forces, std::span<double> grid,
                           std::span<double> impulse) const {
    // Local in space (S delta = (dt^2/mu) f), spread over all modes.
    const double k = force_to_displacement();
    if (forces.size() > transform_threshold_) {
        std::fill(grid.begin(), grid.end(), 0.0);
        for (const auto& [i, f] : forces) grid[i] = k * f;
        basis_.to_modes(grid, impulse);
    } else {
        std::fill(impulse.begin(), impulse.end(), 0.0);
        for (const auto& [i, f] : forces) kernels::axpy(impulse_scale() * f, basis_.row(i).data(), impulse.data(), impulse.size());
    }
}

void Plan::predicted_at(std::span<const std::size_t> points, std::span<const double> predicted,
                        std::span<const double> q, std::span<const double> d, std::span<double> grid) const {
    const std::size_t n = mode_count();
    std::array<const double*, kernels::kMaxRowsPerPass> rows;
    std::array<double, kernels::kMaxRowsPerPass> values;
    for (std::size_t first = 0; first < points.size(); first += rows.size()) {
        const std::size_t m = std::min(rows.size(), points.size() - first);
        for (std::size_t r = 0; r < m; ++r) rows[r] = basis_.row(points[first + r]).data();
        if (predicted.empty())
            kernels::predict_dot_rows(propagator_.decay().data(), propagator_.beta().data(), q.data(), d.data(),
                                      rows.data(), m, n, values.data());
        else
            kernels::dot_rows(rows.data(), m, predicted.data(), n, values.data());
        for (std::size_t r = 0; r < m; ++r) grid[points[first + r]] = values[r];
    }
}

void Plan::prepare_rows() const {
    for (std::size_t i : obstacle_points_) basis_.row(i);
}

ScreeningChoice choose_screening(const Case& c, const PlanOptions& options, bool can_fly) {
    // Few points: solving each costs one row product, about what one update of the speed
    // bound costs, so skipping a few cannot pay for the bookkeeping.
    constexpr std::size_t kFewPoints = 16;
    if (!options.screen_contacts) return {false, "off (asked for)"};
    std::size_t points = 0;
    // Within a micrometre of the rest line (a bridge's curve between grid points), the
    // string keeps touching it while it sounds: free flight comes rarely, if ever.
    constexpr double kRestingGap = 1e-6;
    bool rests_on_it = false;
    // Points off the grid are solved every step (PointContact): with no obstacle on the grid
    // beside them, nothing is left to screen.
    const bool off_grid = std::any_of(c.point_obstacles.begin(), c.point_obstacles.end(),
                                      [&](const PointObstacle& p) { return !joins_grid(c, p, options); });
    if (off_grid && !has_grid_obstacle(c) && options.choose_screening)
        return {false, "off (automatic: exact point obstacles)"};
    const auto count = [&](double h) {
        ++points;
        rests_on_it = rests_on_it || c.contact_orientation() * h >= -kRestingGap;
    };
    for (double h : c.obstacle_height_m)
        if (std::isfinite(h)) count(h);
    for (const PointObstacle& p : c.point_obstacles) count(p.height_m);
    if (!options.choose_screening) return {true, "on (asked for)"};
    if (points <= kFewPoints && (rests_on_it || !can_fly))
        return {false, "off (automatic: obstacle grid points: " + std::to_string(points) + ", " +
                           (rests_on_it ? "the string rests on the obstacle" : "no free flight") + ")"};
    return {true, "on (automatic: obstacle grid points: " + std::to_string(points) + ")"};
}

std::size_t Plan::default_transform_threshold(std::size_t modes, double transform_flops) {
    // One row product is N multiply-adds at about 8 a cycle (8 partial sums, AVX2: 0.11 us
    // for N = 999). The sine transform (a real DFT of 2(N + 1) points) runs about 3800 of
    // FFTW's estimated cost units a microsecond, whatever the factors of N + 1 (measured:
    // N = 999, 1.3e4 units, 3.2 us; N = 862, N + 1 prime, 9.4e4, 16 us; N = 1600, 8.1e4,
    // 24 us): alone, it costs about 2.5 x units / N rows. A step through it also pays a
    // pass over the modes and the copies into the transform, while rows let most due points
    // go back to sleep on their low modes; whole runs (flat obstacle, 400 kHz) were fastest
    // with the switch at 192-256 points for N = 1600 and 3200, where 2.5 put it at 126 and
    // 148: hence 4. FFTW's estimate, not a timing: runs stay reproducible.
    const double rows = 4.0 * transform_flops / static_cast<double>(modes);
    const std::size_t most = std::max<std::size_t>(16, modes / 2);
    if (!std::isfinite(rows)) return most;
    return std::clamp<std::size_t>(static_cast<std::size_t>(rows), 16, most);
}

}  // namespace fretbuzz
