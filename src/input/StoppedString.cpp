#include "fretbuzz/input/StoppedString.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/scheme/HeldString.hpp"

namespace fretbuzz {

namespace {
constexpr double kFarBelow = 5e-3;  // m
Case stopped_from_zero(const Case& open, double stop_m, std::size_t modes, const HeldString::Finger& finger);
}  // namespace

namespace {
// The same string seen from its other end (x -> L - x): phi_j(L - x) = (-1)^(j+1) phi_j(x).
Case mirrored(const Case& c) {
    Case m = c;
    std::reverse(m.obstacle_height_m.begin(), m.obstacle_height_m.end());
    for (PointObstacle& p : m.point_obstacles) p.x_m = c.string.length_m - p.x_m;
    for (std::size_t j = 1; j < m.mode_count(); j += 2) {
        m.initial_displacement[j] = -m.initial_displacement[j];
        m.initial_velocity[j] = -m.initial_velocity[j];
    }
    for (double& x : m.observation_points_m) x = c.string.length_m - x;
    return m;
}
}  // namespace

bool stops_at_far_end(const Case& c) {
    double sum = 0.0;
    std::size_t count = 0;
    for (std::size_t i = 0; i < c.mode_count(); ++i)
        if (std::isfinite(c.obstacle_height_m[i])) {
            sum += c.grid_point(i);
            ++count;
        }
    for (const PointObstacle& p : c.point_obstacles) {
        sum += p.x_m;
        ++count;
    }
    return count > 0 && sum / static_cast<double>(count) < 0.25 * c.string.length_m;
}

HeldString::Finger stopping_finger(const Case& open, double stop_m) {
    const double length = open.string.length_m;
    std::vector<double> frets = open.fret_positions_m;  // as seen from the finger's end
    if (stops_at_far_end(open))
        for (double& x : frets) x = length - x;
    std::sort(frets.begin(), frets.end());
    const auto at = std::find_if(frets.begin(), frets.end(), [&](double x) { return std::abs(x - stop_m) <= 1.5 * open.grid_step(); });
    if (at != frets.end()) {
        const double behind = at == frets.begin() ? 0.0 : *(at - 1);
        return HeldString::Finger::of(finger_behind_fret(stop_m, stop_m - behind), kFretFingerForce, behind);
    }
    // No fret there: the fret before one equal-tempered semitone lower (the nut, if that is
    // within a millimetre of it), the string lying on it only where there is nothing to say
    // otherwise (a string with no obstacle at all, as the set-up bench shortens its strings).
    double before = length - (length - stop_m) * std::exp2(1.0 / 12.0);
    if (before < 1e-3) before = 0.0;
    const bool bare = std::none_of(open.obstacle_height_m.begin(), open.obstacle_height_m.end(), [](double g) { return std::isfinite(g); }) &&
                      open.point_obstacles.empty();
    return HeldString::Finger::of(finger_behind_fret(stop_m, stop_m - before), kFretFingerForce, bare ? before : 0.0);
}

Case stopped_string(const Case& open, double stop_m, std::size_t modes, const HeldString::Finger& finger) {
    if (stop_m > 0.0 && stops_at_far_end(open)) return mirrored(stopped_from_zero(mirrored(open), stop_m, modes, finger));
    return stopped_from_zero(open, stop_m, modes, finger);
}

double fret_stop_m(const Case& open, int fret) {
    if (fret >= 1 && static_cast<std::size_t>(fret) <= open.fret_positions_m.size())
        return open.fret_positions_m[static_cast<std::size_t>(fret - 1)];
    return fret_position(open.string.length_m, fret);
}

Case stopped_string(const Case& open, double stop_m, std::size_t modes) {
    return stopped_string(open, stop_m, modes, stopping_finger(open, stop_m));
}

namespace {
Case stopped_from_zero(const Case& open, double stop_m, std::size_t modes, const HeldString::Finger& finger) {
    const double length = open.string.length_m;
    if (!(stop_m >= 0.0 && stop_m <= 0.75 * length))
        throw InputError(out_of_range_message("stop position (m)", stop_m, "[0, 3 L / 4] (fret 24) with L = " + std::to_string(length)));
    if (modes == 0) throw InputError(out_of_range_message("modes", 0.0, ">= 1"));
    const std::size_t n_open = open.mode_count();
    const std::size_t n = std::min(modes, n_open);
    const double sounding = length - stop_m;

    Case c = open;
    c.name = open.name + (stop_m > 0.0 ? "-stopped" : "");
    c.string.length_m = sounding;
    // The held string's partials (truncated when unstopped); a measured table of the second
    // polarisation the same way, mode for mode.
    const auto sounding_modes = [&](const ModeTable& t) {
        if (stop_m > 0.0) return HeldString(t, length, stop_m).sounding_partials(n, finger, open.string.linear_density);
        ModeTable first = t;
        first.frequency_hz.resize(n);
        first.sigma_per_s.resize(n);
        first.source.resize(n);
        return first;
    };
    c.modes = sounding_modes(open.modes);
    if (open.polarisation.table.size() > 0) c.polarisation.table = sounding_modes(open.polarisation.table);
    c.initial_displacement.assign(n, 0.0);
    c.initial_velocity.assign(n, 0.0);
    if (stop_m == 0.0)
        for (std::size_t j = 0; j < n; ++j) {
            c.initial_displacement[j] = open.initial_displacement[j];
            c.initial_velocity[j] = open.initial_velocity[j];
        }

    // The obstacle on the new grid: nearest point of the open grid (keeps point-like frets
    // at full height when the new grid is finer), relative to the string's new rest line.
    const double dx_open = open.grid_step();
    const auto nearest = [&](double x) {
        const long k = std::lround(x / dx_open) - 1;
        return static_cast<std::size_t>(std::clamp<long>(k, 0, static_cast<long>(n_open) - 1));
    };
    double stop_height = 0.0;  // height of what the string is pressed onto (a fret top)
    if (stop_m > 0.0) {
        stop_height = -std::numeric_limits<double>::infinity();
        const std::size_t k = nearest(stop_m);
        for (std::size_t i = k > 0 ? k - 1 : 0; i <= std::min(k + 1, n_open - 1); ++i)
            stop_height = std::max(stop_height, open.obstacle_height_m[i]);
        for (const PointObstacle& p : open.point_obstacles)  // a fret at its exact position
            if (std::abs(p.x_m - stop_m) <= 1.5 * dx_open) stop_height = std::max(stop_height, p.height_m);
        // Nothing within a few millimetres (no fret there): the finger holds the string at rest height.
        if (!(stop_height > -kFarBelow)) stop_height = 0.0;
    }
    const double dx = sounding / static_cast<double>(n + 1);
    // A fret one open grid step wide may fall between the points of a coarser grid: the point
    // whose cell holds a fret takes the highest open height in its cell (the fret's top), and
    // the fret moves to that point (at most dx / 2).
    // (frets that are exact points stay at their exact positions: see below)
    const auto is_point = [&](double x) {
        return std::any_of(open.point_obstacles.begin(), open.point_obstacles.end(), [x](const PointObstacle& p) { return p.x_m == x; });
    };
    std::vector<double> frets;
    for (double x : open.fret_positions_m)
        if (x - stop_m >= 1.5 * dx_open && !is_point(x)) frets.push_back(x - stop_m);
    const double toward = open.contact_orientation();
    const auto top_of_cell = [&](double s) {
        double best = open.obstacle_height_m[nearest(stop_m + s)];
        for (std::size_t k = nearest(stop_m + s - 0.5 * dx); k <= nearest(stop_m + s + 0.5 * dx); ++k)
            if (toward * open.obstacle_height_m[k] > toward * best) best = open.obstacle_height_m[k];
        return best;
    };
    c.fret_positions_m.clear();
    c.obstacle_height_m.assign(n, -std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < n; ++i) {
        const double s = static_cast<double>(i + 1) * dx;
        if (stop_m > 0.0 && s < 1.5 * dx_open) continue;  // the fret under the finger is the new nut
        const bool fret = std::any_of(frets.begin(), frets.end(), [&](double x) { return x - s > -0.5 * dx && x - s <= 0.5 * dx; });
        if (fret) c.fret_positions_m.push_back(s);
        const double g = fret ? top_of_cell(s) : open.obstacle_height_m[nearest(stop_m + s)];
        if (std::isfinite(g)) c.obstacle_height_m[i] = g - stop_height * (1.0 - s / sounding);
    }
    // Exact points stay where they are on the string (beyond the stop), their widths kept.
    c.point_obstacles.clear();
    for (const PointObstacle& p : open.point_obstacles) {
        const double s = p.x_m - stop_m;
        if (stop_m > 0.0 && s < 1.5 * dx_open) continue;  // under the finger
        if (s > 0.0 && s < sounding) {
            c.point_obstacles.push_back({s, p.height_m - stop_height * (1.0 - s / sounding), p.weight_m});
            if (std::find(open.fret_positions_m.begin(), open.fret_positions_m.end(), p.x_m) != open.fret_positions_m.end())
                c.fret_positions_m.push_back(s);
        }
    }
    std::sort(c.fret_positions_m.begin(), c.fret_positions_m.end());
    c.observation_points_m.clear();
    for (double x : open.observation_points_m)
        if (x > stop_m) c.observation_points_m.push_back(x - stop_m);
    if (c.observation_points_m.empty()) c.observation_points_m.push_back(0.9 * sounding);
    c.validate();
    return c;
}

}  // namespace

}  // namespace fretbuzz
