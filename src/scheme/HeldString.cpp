#include "fretbuzz/scheme/HeldString.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <numeric>
#include <string>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/scheme/SineTransform.hpp"

namespace fretbuzz {

namespace {
constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kTwoPi = 2.0 * std::numbers::pi;
// An open mode with |z_j| below this fraction of the largest has a node at x_h: it is a held mode.
constexpr double kNodeFraction = 1e-10;
// Open modes whose omega^2 differ by less than this fraction act as one pole.
constexpr double kSamePole = 1e-13;
// The explicit part of the compliance above the table: modes N+1 .. kTailFactor N.
constexpr std::size_t kTailFactor = 64;

// Static compliance at x_h of the modes above the table's N: sum z_j^2 / omega_j^2, their
// omega_j from the extrapolated dispersion. Past the explicit terms sin^2 averages 1/2 and the
// sum is the integral (1 / pi) int_K^inf dk / (k^2 c^2(k)), with c^2 = a + b k^2 there.
double tail_compliance(const StringDispersion& dispersion, std::size_t n, double length, double held_at) {
    double sum = 0.0;
    const std::size_t last = kTailFactor * n;
    for (std::size_t j = n + 1; j <= last; ++j) {
        const double k = static_cast<double>(j) * std::numbers::pi / length;
        const double s = std::sin(k * held_at);
        const double omega = kTwoPi * dispersion.frequency_hz(k);
        sum += 2.0 / length * s * s / (omega * omega);
    }
    const double k = (static_cast<double>(last) + 0.5) * std::numbers::pi / length;
    const auto squared_speed = [&](double q) { return std::pow(kTwoPi * dispersion.frequency_hz(q) / q, 2); };
    const double b = (squared_speed(2.0 * k) - squared_speed(k)) / (3.0 * k * k);
    const double a = squared_speed(k) - b * k * k;
    if (!(a > 0.0 && b > 0.0)) return sum + 1.0 / (std::numbers::pi * k * squared_speed(k));
    // int_K^inf dk / (k^2 (a + b k^2)) = (1 - atan(y) / y) / (a K), y = sqrt(a / b) / K.
    const double y = std::sqrt(a / b) / k;
    const double g = y < 1e-3 ? y * y / 3.0 - std::pow(y, 4) / 5.0 : 1.0 - std::atan(y) / y;
    return sum + g / (std::numbers::pi * a * k);
}

// The root in (0, width) of a - b1 / u + b2 / (width - u) (b1, b2 >= 0), or -1 if rounding
// puts it outside.
double two_pole_root(double a, double b1, double b2, double width) {
    const double b = a * width + b1 + b2;
    const double s = std::sqrt(std::max(0.0, b * b - 4.0 * a * b1 * width));
    const double q = 0.5 * (b + std::copysign(s, b));
    for (const double u : {q != 0.0 ? b1 * width / q : -1.0, a != 0.0 ? q / a : -1.0})
        if (u > 0.0 && u < width) return u;
    return -1.0;
}
}  // namespace

HeldString::HeldString(const ModeTable& open, double length_m, double held_at_m)
    : length_m_(length_m), held_at_m_(held_at_m), dispersion_(open, length_m) {
    if (!(held_at_m > 0.0 && held_at_m < length_m))
        throw InputError(out_of_range_message("held point x_h (m)", held_at_m, "(0, L) with L = " + std::to_string(length_m)));
    if (open.size() < 2) throw InputError(out_of_range_message("modes of the held string", static_cast<double>(open.size()), ">= 2"));
    open.validate();
    const std::size_t n = open.size();
    z_.resize(n);
    for (std::size_t j = 0; j < n; ++j)
        z_[j] = std::sqrt(2.0 / length_m) * std::sin(static_cast<double>(j + 1) * std::numbers::pi * held_at_m / length_m);

    // Poles: the open modes in ascending frequency, repeated frequencies as one.
    std::vector<std::size_t> order(n);
    std::iota(order.begin(), order.end(), std::size_t{0});
    const auto squared_omega = [&](std::size_t j) { return std::pow(kTwoPi * open.frequency_hz[j], 2); };
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return squared_omega(a) < squared_omega(b); });
    group_of_.resize(n);
    for (const std::size_t j : order) {
        const double d = squared_omega(j);
        if (groups_.empty() || d - groups_.back().squared_omega > kSamePole * d) groups_.push_back({d, 0.0, {}, false});
        groups_.back().members.push_back(j);
        groups_.back().weight += z_[j] * z_[j];
        group_of_[j] = groups_.size() - 1;
    }
    // The held modes up to half the open table's highest frequency, and a window's worth above.
    trusted_below_hz_ = 0.5 * *std::max_element(open.frequency_hz.begin(), open.frequency_hz.end());
    static_compliance_ = tail_compliance(dispersion_, n, length_m, held_at_m);
    find_roots(std::pow(kTwoPi * trusted_below_hz_, 2));

    // Each held mode's vector and near-side samples, and its overlaps with the next 2 w (a
    // window's worth): on the near side, and through the open dampings.
    const SineTransform transform(n);
    const double dx = length_m / static_cast<double>(n + 1);
    // Grid points x_i = i dx < x_h (the one at x_h, if any, has u = 0).
    const std::size_t near_points = static_cast<std::size_t>(std::max(1.0, std::ceil(held_at_m / dx - 1e-9))) - 1;
    const std::size_t count = roots_.size();
    std::vector<std::vector<double>> vectors(count), near_samples(count);
    std::vector<double> samples(n);
    for (std::size_t r = 0; r < count; ++r) {
        vectors[r] = coefficients(roots_[r]);
        transform.apply(vectors[r], samples, 0.5 * std::sqrt(2.0 / length_m));
        near_samples[r].assign(samples.begin(), samples.begin() + static_cast<std::ptrdiff_t>(near_points));
    }
    near_band_.assign(count, std::vector<double>(2 * kWindowHalfWidth + 1, 0.0));
    damping_band_ = near_band_;
    for (std::size_t m = 0; m < count; ++m) {
        for (std::size_t d = 0; d <= 2 * kWindowHalfWidth && m + d < count; ++d) {
            double near = 0.0, damping = 0.0;
            for (std::size_t i = 0; i < near_points; ++i) near += near_samples[m][i] * near_samples[m + d][i];
            for (std::size_t j = 0; j < n; ++j) damping += vectors[m][j] * vectors[m + d][j] * open.sigma_per_s[j];
            near_band_[m][d] = dx * near;
            damping_band_[m][d] = damping;
        }
        modes_.push_back({std::sqrt(roots_[m].squared_omega) / kTwoPi, damping_band_[m][0], near_band_[m][0]});
    }
}

void HeldString::find_roots(double trusted_squared_omega) {
    double largest = 0.0;
    for (const double z : z_) largest = std::max(largest, std::abs(z));
    // Poles with weight: the secular equation's; the others' members stay modes as they are.
    std::vector<std::size_t> active;
    for (std::size_t g = 0; g < groups_.size(); ++g) {
        Group& group = groups_[g];
        group.active = std::sqrt(group.weight) > kNodeFraction * largest;
        if (!group.active) {
            for (const std::size_t j : group.members) roots_.push_back({group.squared_omega, g, 0.0, {{j, 1.0}}});
            continue;
        }
        active.push_back(g);
        // A repeated frequency: the combinations of its members orthogonal to z are held modes.
        const auto size = static_cast<Eigen::Index>(group.members.size());
        if (size > 1) {
            Eigen::VectorXd zg(size);
            for (Eigen::Index i = 0; i < size; ++i) zg(i) = z_[group.members[static_cast<std::size_t>(i)]];
            const Eigen::MatrixXd q = Eigen::HouseholderQR<Eigen::MatrixXd>(zg).householderQ();
            for (Eigen::Index c = 1; c < size; ++c) {
                Root r{group.squared_omega, g, 0.0, {}};
                for (Eigen::Index i = 0; i < size; ++i) r.deflated.emplace_back(group.members[static_cast<std::size_t>(i)], q(i, c));
                roots_.push_back(std::move(r));
            }
        }
    }
    // One root between each two consecutive poles (none below the first; the one above the
    // last belongs to the extrapolated tail and is left out), up to w + 1 poles above the
    // trusted range. Newton-like steps on a model with the two bracketing poles (exact for
    // them, the others folded into a constant and their slope), inside a bisection bracket.
    const std::size_t poles = active.size();
    std::size_t last = 0;
    while (last + 1 < poles && groups_[active[last]].squared_omega <= trusted_squared_omega) ++last;
    last = std::min(poles - 1, last + kWindowHalfWidth + 1);
    std::vector<double> delta(poles), weight(poles);
    for (std::size_t p = 0; p < poles; ++p) weight[p] = groups_[active[p]].weight;
    for (std::size_t p = 0; p < last; ++p) {
        const double width = groups_[active[p + 1]].squared_omega - groups_[active[p]].squared_omega;
        const auto shift_to = [&](std::size_t origin) {
            for (std::size_t q = 0; q < poles; ++q)
                delta[q] = groups_[active[q]].squared_omega - groups_[active[origin]].squared_omega;
        };
        shift_to(p);
        double at_middle = static_compliance_;
        for (std::size_t q = 0; q < poles; ++q) at_middle += weight[q] / (delta[q] - 0.5 * width);
        // Offsets from the nearer pole: the root's distance to it keeps full precision.
        const std::size_t origin = at_middle >= 0.0 ? p : p + 1;
        if (origin != p) shift_to(origin);
        double lo = origin == p ? 0.0 : -0.5 * width, hi = origin == p ? 0.5 * width : 0.0;
        const double below = delta[p], above = delta[p + 1];
        double t = 0.5 * (lo + hi);
        for (int iteration = 0; iteration < 200; ++iteration) {
            double low_sum = 0.0, low_slope = 0.0, high_sum = static_compliance_, high_slope = 0.0, size = static_compliance_;
            for (std::size_t q = 0; q < poles; ++q) {
                const double r = delta[q] - t;
                const double term = weight[q] / r;
                size += std::abs(term);
                if (q <= p) {
                    low_sum += term;
                    low_slope += term / r;
                } else {
                    high_sum += term;
                    high_slope += term / r;
                }
            }
            const double f = low_sum + high_sum;
            if (std::abs(f) <= 8.0 * kEps * size || hi - lo <= 4.0 * kEps * std::max(std::abs(lo), std::abs(hi))) break;
            (f > 0.0 ? hi : lo) = t;
            const double b1 = low_slope * (below - t) * (below - t), b2 = high_slope * (above - t) * (above - t);
            const double a = low_sum - b1 / (below - t) + high_sum - b2 / (above - t);
            const double u = two_pole_root(a, b1, b2, above - below);
            double next = below + u;
            if (u < 0.0 || next < lo || next > hi) next = 0.5 * (lo + hi);
            if (std::abs(next - t) <= 2.0 * kEps * std::abs(next)) {
                t = next;
                break;
            }
            t = next;
        }
        roots_.push_back({groups_[active[origin]].squared_omega + t, active[origin], t, {}});
    }
    // The deflated modes above the range go.
    const double top = poles > 0 ? groups_[active[last]].squared_omega : trusted_squared_omega;
    std::erase_if(roots_, [&](const Root& r) { return !r.deflated.empty() && r.squared_omega > top; });
    std::stable_sort(roots_.begin(), roots_.end(), [](const Root& a, const Root& b) { return a.squared_omega < b.squared_omega; });
}

std::vector<double> HeldString::coefficients(const Root& r) const {
    std::vector<double> a(z_.size(), 0.0);
    if (!r.deflated.empty()) {
        for (const auto& [j, value] : r.deflated) a[j] = value;
        return a;
    }
    const double origin = groups_[r.origin].squared_omega;
    double norm = 0.0;
    for (std::size_t j = 0; j < z_.size(); ++j) {
        const Group& g = groups_[group_of_[j]];
        if (!g.active) continue;
        a[j] = z_[j] / ((g.squared_omega - origin) - r.offset);
        norm += a[j] * a[j];
    }
    for (double& v : a) v /= std::sqrt(norm);
    return a;
}

ModeTable HeldString::pinned_partials(std::size_t count) const {
    return dispersion_.pinned_modes(length_m_ - held_at_m_, count);
}

ModeTable HeldString::sounding_partials(std::size_t count) const {
    const ModeTable pinned = pinned_partials(count);
    ModeTable out = pinned;
    const std::size_t kept = modes_.size();
    double ratio = 1.0, previous = 0.0;
    for (std::size_t n = 0; n < count; ++n) {
        const double guess = pinned.frequency_hz[n];
        out.frequency_hz[n] = guess * ratio;
        if (guess > trusted_below_hz_ || kept == 0) continue;
        // The window of held modes around the guess.
        const auto nearest = std::min_element(modes_.begin(), modes_.end(), [&](const Mode& a, const Mode& b) {
            return std::abs(a.frequency_hz - guess) < std::abs(b.frequency_hz - guess);
        });
        const auto centre = static_cast<std::size_t>(nearest - modes_.begin());
        const std::size_t lo = centre >= kWindowHalfWidth ? centre - kWindowHalfWidth : 0;
        const std::size_t hi = std::min(kept, centre + kWindowHalfWidth + 1);
        const auto w = static_cast<Eigen::Index>(hi - lo);
        // In units of the guess's omega: q'' + (2 C / omega + 2 zeta S) q' + (Omega / omega)^2 q = 0.
        const double omega = kTwoPi * guess;
        Eigen::MatrixXd near(w, w), damping(w, w);
        for (Eigen::Index r = 0; r < w; ++r)
            for (Eigen::Index c = r; c < w; ++c) {
                const auto m = lo + static_cast<std::size_t>(r);
                const auto d = static_cast<std::size_t>(c - r);
                near(r, c) = near(c, r) = near_band_[m][d];
                damping(r, c) = damping(c, r) = damping_band_[m][d];
            }
        Eigen::MatrixXd state = Eigen::MatrixXd::Zero(2 * w, 2 * w);
        state.topRightCorner(w, w).setIdentity();
        for (Eigen::Index r = 0; r < w; ++r)
            state(w + r, r) = -std::pow(modes_[lo + static_cast<std::size_t>(r)].frequency_hz / guess, 2);
        state.bottomRightCorner(w, w) = -(2.0 / omega) * damping - 2.0 * kNearSideDampingRatio * near;
        const Eigen::EigenSolver<Eigen::MatrixXd> solver(state);
        double best = std::numeric_limits<double>::infinity();
        for (Eigen::Index k = 0; k < 2 * w; ++k) {
            const std::complex<double> lambda = solver.eigenvalues()(k);
            if (lambda.imag() <= 0.0) continue;
            const Eigen::VectorXcd v = solver.eigenvectors().col(k).head(w);
            const double norm = v.squaredNorm();
            if ((v.adjoint() * near * v)(0).real() / norm >= 0.5) continue;  // a near-side mode
            const double f = std::abs(lambda) * guess;
            if (f <= previous * (1.0 + 1e-12) || std::abs(std::log(f / guess)) >= best) continue;
            best = std::abs(std::log(f / guess));
            out.frequency_hz[n] = f;
            out.sigma_per_s[n] = (v.adjoint() * damping * v)(0).real() / norm;
        }
        ratio = out.frequency_hz[n] / guess;
        previous = out.frequency_hz[n];
    }
    return out;
}

}  // namespace fretbuzz
