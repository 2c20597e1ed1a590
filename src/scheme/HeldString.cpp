#include "fretbuzz/scheme/HeldString.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <string>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/numerics/SineTransform.hpp"
#include "fretbuzz/numerics/TimeProfile.hpp"

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
// A partial with the finger is refined until it moves by less than this fraction.
constexpr double kSettled = 1e-12;
// Partials solved one by one, then a partial number kSolvedSpacing times the last solved's.
constexpr std::size_t kSolvedPartials = 40;
constexpr double kSolvedSpacing = 1.05;

// Static compliance between a and b of the modes above the table's N: sum phi_j(a) phi_j(b) /
// omega_j^2, their omega_j from the extrapolated dispersion. Past the explicit terms, at a = b,
// sin^2 averages 1/2 and the sum is the integral (1 / pi) int_K^inf dk / (k^2 c^2(k)), with
// c^2 = a + b k^2 there; at a != b the remainder oscillates and is left out.
double tail_compliance(const StringDispersion& dispersion, std::size_t n, double length, double a_m, double b_m) {
    double sum = 0.0;
    const std::size_t last = kTailFactor * n;
    for (std::size_t j = n + 1; j <= last; ++j) {
        const double k = static_cast<double>(j) * std::numbers::pi / length;
        const double omega = kTwoPi * dispersion.frequency_hz(k);
        sum += 2.0 / length * std::sin(k * a_m) * std::sin(k * b_m) / (omega * omega);
    }
    if (a_m != b_m) return sum;
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
    static_compliance_ = tail_compliance(dispersion_, n, length_m, held_at_m, held_at_m);
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

HeldString::Finger HeldString::Finger::of(const FingerSpec& spec, double force_n, double behind_m) {
    return {spec.position_m, spec.width_m, spec.mass_kg, spec.stiffness, spec.exponent, spec.loss, force_n, behind_m};
}

namespace {
// The finger's attachments on the grid: the fret behind x_h (if any) first, then the pad.
struct Attachments {
    std::vector<double> x;  // m
    std::size_t held = 0;   // how many of them are held (0 or 1)
    double spring = 0.0, damper = 0.0, mass = 0.0;  // per pad point and per unit length of string
};

Attachments attach(const HeldString::Finger& f, double length, std::size_t n, double held_at, double density) {
    const auto require = [](bool ok, const std::string& name, double value, const std::string& range) {
        if (!ok) throw InputError(out_of_range_message(name, value, range));
    };
    require(density > 0.0, "string linear density (kg/m)", density, "> 0");
    require(f.mass_kg > 0.0, "finger mass (kg)", f.mass_kg, "> 0");
    require(f.stiffness > 0.0, "finger stiffness (N/m^alpha)", f.stiffness, "> 0");
    require(f.exponent >= 1.0, "finger exponent", f.exponent, ">= 1");
    require(f.loss >= 0.0, "finger loss (s/m)", f.loss, ">= 0");
    require(f.force_n > 0.0, "finger pressing force (N)", f.force_n, "> 0");
    require(f.behind_m >= 0.0 && f.behind_m < held_at, "fret behind the stop (m)", f.behind_m,
            "[0, x_h) with x_h = " + std::to_string(held_at) + " (0: none)");
    Attachments a;
    if (f.behind_m > 0.0) {
        a.x.push_back(f.behind_m);
        a.held = 1;
    }
    const double dx = length / static_cast<double>(n + 1);
    for (const std::size_t i : pad_points(f.pad_centre_m, f.pad_width_m, dx, n)) {
        const double x = static_cast<double>(i + 1) * dx;
        require(x > f.behind_m && x < held_at, "finger pad point (m)", x,
                "between the fret behind (" + std::to_string(f.behind_m) + ") and the stop (" + std::to_string(held_at) + ")");
        a.x.push_back(x);
    }
    // Each pad point carries F / p at the compression eta = (F / K_f)^(1 / alpha).
    const auto p = static_cast<double>(a.x.size() - a.held);
    const double eta = std::pow(f.force_n / f.stiffness, 1.0 / f.exponent);
    a.spring = f.exponent * f.stiffness / p * std::pow(eta, f.exponent - 1.0) / density;
    a.damper = f.loss * f.force_n / p / density;
    a.mass = f.mass_kg / density;
    return a;
}

using Band = std::vector<std::vector<double>>;

// The window's symmetric matrix from a band of overlaps (row m: m with m + d).
Eigen::MatrixXd window_matrix(const Band& band, std::size_t lo, std::size_t w) {
    Eigen::MatrixXd out(static_cast<Eigen::Index>(w), static_cast<Eigen::Index>(w));
    for (std::size_t r = 0; r < w; ++r)
        for (std::size_t c = r; c < w; ++c)
            out(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = out(static_cast<Eigen::Index>(c), static_cast<Eigen::Index>(r)) =
                band[lo + r][c - r];
    return out;
}

// The held modes of a window with the finger attached, the other held modes as their
// receptance at the attachments at s (rad/s; each with its own damping), in units of unit
// (s = unit s^, forces unit^2 g^). Unknowns: the window's coordinates y and velocities v^,
// the attachments' forces g^ per unit mass of string, the finger's height z and velocity z':
//   s^ y = v^,   s^ v^ = -(Omega / unit)^2 y - (2 D / unit) v^ + Psi^T g^,
//   0 = Psi_b y + unit^2 R_b g^                            (the fret behind: u = 0),
//   0 = g^_i + (k^ + c^ s^) (Psi_i y + unit^2 R_i g^ - z)  (a pad point),
//   s^ z = z',   M s^ z' = -sum_pad g^,
// A x = s^ B x (B singular: the attachments' rows are algebraic); with R taken at the
// eigenvalue s itself it is the exact (nonlinear) problem of the held string with the finger.
struct Pencil {
    double unit = 0.0;
    std::size_t lo = 0, w = 0;  // the window: held modes lo .. lo + w - 1
    Eigen::MatrixXcd a, b;
};

Pencil finger_pencil(const std::vector<HeldString::Mode>& modes, const Band& damping_band, const Attachments& at,
                     const Eigen::MatrixXd& psi, const Eigen::MatrixXd& rest, std::size_t lo, std::size_t w, double unit,
                     std::complex<double> s) {
    const std::size_t kept = modes.size();
    Pencil p;
    p.unit = unit;
    p.lo = lo;
    p.w = w;
    Eigen::VectorXcd outside(static_cast<Eigen::Index>(kept));
    for (std::size_t m = 0; m < kept; ++m) {
        const double omega = kTwoPi * modes[m].frequency_hz;
        outside(static_cast<Eigen::Index>(m)) = m >= lo && m < lo + w ? 0.0 : 1.0 / (omega * omega + 2.0 * modes[m].sigma_per_s * s + s * s);
    }
    const Eigen::MatrixXcd flexibility =
        (unit * unit) * (rest.cast<std::complex<double>>() + psi.transpose() * outside.asDiagonal() * psi);
    const auto W = static_cast<Eigen::Index>(w), P = static_cast<Eigen::Index>(at.x.size());
    const Eigen::MatrixXd window = psi.middleRows(static_cast<Eigen::Index>(lo), W);
    const Eigen::Index y = 0, v = W, g = 2 * W, z = 2 * W + P, zv = z + 1, size = zv + 1;
    p.a = Eigen::MatrixXcd::Zero(size, size);
    p.b = Eigen::MatrixXcd::Zero(size, size);
    p.a.block(y, v, W, W).setIdentity();
    p.b.block(y, y, W, W).setIdentity();
    for (Eigen::Index r = 0; r < W; ++r) p.a(v + r, y + r) = -std::pow(kTwoPi * modes[lo + static_cast<std::size_t>(r)].frequency_hz / unit, 2);
    p.a.block(v, v, W, W) = (-(2.0 / unit) * window_matrix(damping_band, lo, w)).cast<std::complex<double>>();
    p.a.block(v, g, W, P) = window.cast<std::complex<double>>();
    p.b.block(v, v, W, W).setIdentity();
    const double spring = at.spring / (unit * unit), damper = at.damper / unit;
    for (Eigen::Index q = 0; q < P; ++q) {
        if (static_cast<std::size_t>(q) < at.held) {
            p.a.block(g + q, y, 1, W) = window.col(q).transpose().cast<std::complex<double>>();
            p.a.block(g + q, g, 1, P) = flexibility.row(q);
            continue;
        }
        p.a.block(g + q, y, 1, W) = (spring * window.col(q).transpose()).cast<std::complex<double>>();
        p.a.block(g + q, v, 1, W) = (damper * window.col(q).transpose()).cast<std::complex<double>>();
        p.a.block(g + q, g, 1, P) = spring * flexibility.row(q);
        p.a(g + q, g + q) += 1.0;
        p.a(g + q, z) = -spring;
        p.a(g + q, zv) = -damper;
        p.b.block(g + q, g, 1, P) = -damper * flexibility.row(q);
        p.a(zv, g + q) = -1.0;
    }
    p.a(z, zv) = 1.0;
    p.b(z, z) = 1.0;
    p.b(zv, zv) = at.mass;
    return p;
}

// The sounding partial nearest to `target` (rad/s) and above `above`: among the eigenvalues of
// the pencil of the window around the target, its receptance taken at s = i target (real:
// Eigen's QZ), the complex mode with most of its energy on the far side; then refined by
// inverse iteration (shift updated each step) on the pencil with the receptance taken at the
// eigenvalue found, until it stays: the root of the exact problem.
std::optional<std::complex<double>> partial_with_finger(const std::vector<HeldString::Mode>& modes, const Band& near_band,
                                                        const Band& damping_band, const Attachments& at,
                                                        const Eigen::MatrixXd& psi, const Eigen::MatrixXd& rest, double target,
                                                        double above) {
    const std::size_t kept = modes.size(), half = HeldString::kWindowHalfWidth;
    const auto nearest = std::min_element(modes.begin(), modes.end(), [&](const auto& x, const auto& y) {
        return std::abs(kTwoPi * x.frequency_hz - target) < std::abs(kTwoPi * y.frequency_hz - target);
    });
    const auto centre = static_cast<std::size_t>(nearest - modes.begin());
    const std::size_t lo = centre >= half ? centre - half : 0, w = std::min(kept, centre + half + 1) - lo;
    const Pencil p = finger_pencil(modes, damping_band, at, psi, rest, lo, w, target, {0.0, target});
    const Eigen::GeneralizedEigenSolver<Eigen::MatrixXd> solver(p.a.real(), p.b.real(), true);
    const Eigen::MatrixXd near = window_matrix(near_band, lo, w);
    double best = std::numeric_limits<double>::infinity();
    std::optional<std::complex<double>> s;  // in units of target
    Eigen::VectorXcd x;
    for (Eigen::Index k = 0; k < p.a.rows(); ++k) {
        const std::complex<double> alpha = solver.alphas()(k);
        const double beta = solver.betas()(k);
        if (!(std::abs(beta) > 1e-12 * std::abs(alpha))) continue;  // infinite: an algebraic row
        const std::complex<double> candidate = alpha / beta;
        const double f = std::abs(candidate) * target;
        if (candidate.imag() <= 0.0 || f <= above * (1.0 + 1e-12) || std::abs(std::log(f / target)) >= best) continue;
        const Eigen::VectorXcd coordinates = solver.eigenvectors().col(k).head(static_cast<Eigen::Index>(w));
        if ((coordinates.adjoint() * near * coordinates)(0).real() / coordinates.squaredNorm() >= 0.5) continue;  // a near-side mode
        best = std::abs(std::log(f / target));
        s = candidate;
        x = solver.eigenvectors().col(k).normalized();
    }
    if (!s) return std::nullopt;
    for (int step = 0; step < 20; ++step) {
        const Pencil exact = finger_pencil(modes, damping_band, at, psi, rest, lo, w, target, *s * target);
        const Eigen::VectorXcd d = (exact.a - *s * exact.b).partialPivLu().solve(exact.b * x);
        const std::complex<double> next = *s + x.squaredNorm() / x.dot(d);
        x = d.normalized();
        const bool settled = std::abs(next - *s) <= kSettled * std::abs(next);
        s = next;
        if (settled) break;
    }
    if (!(std::isfinite(s->real()) && std::isfinite(s->imag()))) return std::nullopt;
    return *s * target;
}

}  // namespace

ModeTable HeldString::sounding_partials(std::size_t count, const Finger& finger, double linear_density) const {
    const std::size_t n = z_.size();
    const Attachments at = attach(finger, length_m_, n, held_at_m_, linear_density);
    const std::size_t points = at.x.size(), kept = modes_.size();
    // The held modes at the attachments, psi(m, q), from their open-mode vectors.
    Eigen::MatrixXd phi(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(points));
    for (std::size_t j = 0; j < n; ++j)
        for (std::size_t q = 0; q < points; ++q)
            phi(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(q)) =
                std::sqrt(2.0 / length_m_) * std::sin(static_cast<double>(j + 1) * std::numbers::pi * at.x[q] / length_m_);
    Eigen::MatrixXd psi(static_cast<Eigen::Index>(kept), static_cast<Eigen::Index>(points));
    for (std::size_t m = 0; m < kept; ++m) {
        const std::vector<double> a = coefficients(roots_[m]);
        psi.row(static_cast<Eigen::Index>(m)) = Eigen::Map<const Eigen::VectorXd>(a.data(), static_cast<Eigen::Index>(n)).transpose() * phi;
    }
    // Static flexibility at the attachments of the string held at x_h: the open modes' (the
    // tail above the table at the held points), less the part through x_h; less the held modes
    // kept, whose share is dynamic (below). What is left: the held modes never computed.
    std::vector<double> with_h = at.x;
    with_h.push_back(held_at_m_);
    const auto all = static_cast<Eigen::Index>(points + 1);
    Eigen::MatrixXd phi_h(static_cast<Eigen::Index>(n), all);
    phi_h << phi, Eigen::Map<const Eigen::VectorXd>(z_.data(), static_cast<Eigen::Index>(n));
    Eigen::VectorXd inverse_squared(static_cast<Eigen::Index>(n));
    for (std::size_t j = 0; j < n; ++j) inverse_squared(static_cast<Eigen::Index>(j)) = 1.0 / groups_[group_of_[j]].squared_omega;
    Eigen::MatrixXd g = phi_h.transpose() * inverse_squared.asDiagonal() * phi_h;
    for (Eigen::Index a = 0; a < all; ++a)
        for (Eigen::Index b = a; b < all; ++b) {
            const bool held_a = a == all - 1 || static_cast<std::size_t>(a) < at.held;
            const bool held_b = b == all - 1 || static_cast<std::size_t>(b) < at.held;
            if (!(held_a && held_b)) continue;  // a pad point's spring is soft against the tail
            const double t = a == all - 1 && b == all - 1
                                 ? static_compliance_
                                 : tail_compliance(dispersion_, n, length_m_, with_h[static_cast<std::size_t>(a)], with_h[static_cast<std::size_t>(b)]);
            g(a, b) += t;
            if (a != b) g(b, a) += t;
        }
    const auto p = static_cast<Eigen::Index>(points);
    Eigen::MatrixXd rest = g.topLeftCorner(p, p) - g.topRightCorner(p, 1) * g.bottomLeftCorner(1, p) / g(p, p);
    Eigen::VectorXd held_inverse(static_cast<Eigen::Index>(kept));
    for (std::size_t m = 0; m < kept; ++m) held_inverse(static_cast<Eigen::Index>(m)) = 1.0 / roots_[m].squared_omega;
    rest -= psi.transpose() * held_inverse.asDiagonal() * psi;

    const ModeTable pinned = pinned_partials(count);
    ModeTable out = pinned;
    // Solved: the first kSolvedPartials, then every partial a step of kSolvedSpacing above the
    // last solved; in between, the held-to-pinned ratio and the finger's share of the damping
    // interpolated linearly (above the trusted range: the last solved's, kept).
    double ratio = 1.0, excess = 0.0;
    std::size_t solved = 0;  // partials up to here are set
    for (std::size_t k = 0; k < count; ++k) {
        const double guess = pinned.frequency_hz[k];
        if (guess > trusted_below_hz_ || kept == 0) break;
        if (k >= kSolvedPartials && static_cast<double>(k + 1) < kSolvedSpacing * static_cast<double>(solved) && k + 1 < count) continue;
        const double previous = solved > 0 ? out.frequency_hz[solved - 1] : 0.0;
        const std::optional<std::complex<double>> found =
            partial_with_finger(modes_, near_band_, damping_band_, at, psi, rest, kTwoPi * guess * ratio, kTwoPi * previous);
        if (!found) continue;
        const double next_ratio = std::abs(*found) / kTwoPi / guess, next_excess = -found->real() - pinned.sigma_per_s[k];
        for (std::size_t i = solved; i <= k; ++i) {
            const double t = static_cast<double>(i + 1 - solved) / static_cast<double>(k + 1 - solved);
            out.frequency_hz[i] = pinned.frequency_hz[i] * (ratio + t * (next_ratio - ratio));
            out.sigma_per_s[i] = pinned.sigma_per_s[i] + excess + t * (next_excess - excess);
        }
        ratio = next_ratio;
        excess = next_excess;
        solved = k + 1;
    }
    for (std::size_t i = solved; i < count; ++i) {
        out.frequency_hz[i] = pinned.frequency_hz[i] * ratio;
        out.sigma_per_s[i] = pinned.sigma_per_s[i] + excess;
    }
    return out;
}

}  // namespace fretbuzz
