#include "fretbuzz/analysis/DecaySpectrum.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <unsupported/Eigen/LevenbergMarquardt>

namespace fretbuzz {

namespace {

using std::numbers::pi;
using Complex = std::complex<double>;

// g_k = (1 - z^N) / (1 - z u_k) for z = exp(-alpha + i theta), and dg_k/ds (s = log z),
// bin by bin: what depends on the pole alone is formed once.
struct Kernel {
    Complex value, derivative;
};

class PoleKernel {
public:
    PoleKernel(double alpha, double theta, std::size_t n)
        : n_(static_cast<double>(n)), theta_(theta), shrink_(std::exp(-alpha)), shrink_m1_(std::expm1(-alpha)) {
        const double turn = std::remainder(theta * n_, 2.0 * pi);
        head_ = one_minus_exp(std::expm1(-alpha * n_), std::exp(-alpha * n_), turn);  // 1 - z^N
    }
    // 1 - z u_k.
    Complex step(std::size_t k) const {
        return one_minus_exp(shrink_m1_, shrink_, theta_ - 2.0 * pi * static_cast<double>(k) / n_);
    }
    Complex value(Complex step) const { return head_ * std::conj(step) / std::norm(step); }
    Kernel at(std::size_t k) const {
        const Complex s = step(k);
        const Complex zn = 1.0 - head_, zu = 1.0 - s;
        const Complex inverse = std::conj(s) / std::norm(s);  // no inf/nan cases: |1 - z u_k| > 0 for decay > 0
        const Complex v = head_ * inverse;
        return {v, (-n_ * zn + v * zu) * inverse};
    }

private:
    // 1 - e^a e^(i b) from expm1(a) and e^a, accurate where a and b are both small (a
    // partial's own bins): e^a cos b - 1 = expm1(a) cos b - 2 sin^2(b/2).
    static Complex one_minus_exp(double expm1_a, double exp_a, double b) {
        const double s = std::sin(0.5 * b), c = std::cos(0.5 * b);
        return {-(expm1_a * (1.0 - 2.0 * s * s) - 2.0 * s * s), -exp_a * 2.0 * s * c};
    }
    double n_, theta_, shrink_, shrink_m1_;
    Complex head_;
};

// Each partial's parameters as the fit sees them, scaled to order one: the decay over the
// record (alpha N), the angle in bins (theta N / 2 pi) and the amplitude over `scale`.
constexpr int kPerPartial = 4;
// From ESPRIT's poles the fit converges in a few steps; a second partial where the data hold
// none wanders for ever, and the cap ends that.
constexpr int kEvaluations = 60;
constexpr int kBackground = 4;
// Round-off in the spectrum and in the model (every other partial's leakage subtracted)
// reaches 1e-10 of the largest bin; a residual below 1e-9 of it (180 dB) is taken for
// that, not for noise (a noiseless signal would otherwise make every wiggle of round-off a
// "significant" second partial).
constexpr double kPrecision = 1e-9;

class Residuals : public Eigen::DenseFunctor<double> {
public:
    Residuals(const DecaySpectrum& spectrum, std::size_t first, const Eigen::VectorXcd& data, int partials,
              double scale)
        : Eigen::DenseFunctor<double>(partials * kPerPartial + kBackground, 2 * static_cast<int>(data.size())),
          spectrum_(spectrum), first_(first), data_(data), partials_(partials), scale_(scale) {}

    double to_decay(double u) const { return u / length(); }
    double to_angle(double u) const { return 2.0 * pi * u / length(); }
    double length() const { return static_cast<double>(spectrum_.length()); }
    double scale() const { return scale_; }
    double centre(Eigen::Index i) const {
        return (static_cast<double>(i) - 0.5 * static_cast<double>(data_.size() - 1)) /
               static_cast<double>(std::max<Eigen::Index>(1, data_.size()));
    }

    // The partials' kernels at x: each pole and its mirror.
    std::vector<PoleKernel> kernels(const Eigen::VectorXd& x) const {
        std::vector<PoleKernel> out;
        for (int p = 0; p < partials_; ++p) {
            const double alpha = to_decay(x(kPerPartial * p)), theta = to_angle(x(kPerPartial * p + 1));
            out.emplace_back(alpha, theta, spectrum_.length());
            out.emplace_back(alpha, -theta, spectrum_.length());
        }
        return out;
    }

    int operator()(const Eigen::VectorXd& x, Eigen::VectorXd& f) const {
        const Eigen::Index m = data_.size();
        const std::vector<PoleKernel> kernel = kernels(x);
        for (Eigen::Index i = 0; i < m; ++i) {
            const std::size_t k = first_ + static_cast<std::size_t>(i);
            Complex model = scale_ * (Complex(x(kPerPartial * partials_), x(kPerPartial * partials_ + 1)) +
                                      centre(i) * Complex(x(kPerPartial * partials_ + 2), x(kPerPartial * partials_ + 3)));
            for (int p = 0; p < partials_; ++p) {
                const Complex c = scale_ * Complex(x(kPerPartial * p + 2), x(kPerPartial * p + 3));
                const auto q = static_cast<std::size_t>(2 * p);
                model += c * kernel[q].at(k).value + std::conj(c) * kernel[q + 1].at(k).value;
            }
            const Complex r = model - data_(i);
            f(i) = r.real();
            f(m + i) = r.imag();
        }
        return 0;
    }

    int df(const Eigen::VectorXd& x, Eigen::MatrixXd& jacobian) const {
        const Eigen::Index m = data_.size();
        jacobian.setZero(2 * m, inputs());
        const auto put = [&](Eigen::Index row, Eigen::Index col, Complex d) {
            jacobian(row, col) = d.real();
            jacobian(m + row, col) = d.imag();
        };
        const std::vector<PoleKernel> kernel = kernels(x);
        for (Eigen::Index i = 0; i < m; ++i) {
            const std::size_t k = first_ + static_cast<std::size_t>(i);
            const Eigen::Index b = kPerPartial * partials_;
            put(i, b, scale_);
            put(i, b + 1, Complex(0.0, scale_));
            put(i, b + 2, scale_ * centre(i));
            put(i, b + 3, Complex(0.0, scale_ * centre(i)));
            for (int p = 0; p < partials_; ++p) {
                const Complex c = scale_ * Complex(x(kPerPartial * p + 2), x(kPerPartial * p + 3));
                const auto q = static_cast<std::size_t>(2 * p);
                const Kernel up = kernel[q].at(k), down = kernel[q + 1].at(k);
                // s = -alpha + i theta for the partial, its mirror conj(s) = -alpha - i theta.
                const Complex by_s = c * up.derivative, by_conj_s = std::conj(c) * down.derivative;
                put(i, kPerPartial * p, -(by_s + by_conj_s) / length());
                put(i, kPerPartial * p + 1, Complex(0.0, 1.0) * (by_s - by_conj_s) * (2.0 * pi / length()));
                put(i, kPerPartial * p + 2, scale_ * (up.value + down.value));
                put(i, kPerPartial * p + 3, Complex(0.0, scale_) * (up.value - down.value));
            }
        }
        return 0;
    }

private:
    const DecaySpectrum& spectrum_;
    std::size_t first_;
    const Eigen::VectorXcd& data_;
    int partials_;
    double scale_;
};

}  // namespace

DecaySpectrum::DecaySpectrum(std::span<const std::complex<double>> spectrum, std::size_t length)
    : spectrum_(spectrum), length_(length) {
    if (spectrum.size() != length / 2 + 1 || length < 4) throw std::invalid_argument("DecaySpectrum: bins 0..N/2 needed");
    double top = 0.0;
    for (const Complex& x : spectrum) top = std::max(top, std::norm(x));
    floor_per_bin_ = kPrecision * kPrecision * top;
}

std::complex<double> DecaySpectrum::of(const DampedPartial& p, std::size_t k) const {
    return p.amplitude * PoleKernel(p.decay, p.angle, length_).at(k).value +
           std::conj(p.amplitude) * PoleKernel(p.decay, -p.angle, length_).at(k).value;
}

std::vector<std::complex<double>> DecaySpectrum::bins_without(std::size_t first, std::size_t last,
                                                             std::span<const DampedPartial> others) const {
    std::vector<Complex> out(spectrum_.begin() + static_cast<std::ptrdiff_t>(first),
                             spectrum_.begin() + static_cast<std::ptrdiff_t>(std::min(last, last_bin()) + 1));
    // z u_(k+1) = z u_k e^(-2 pi i / N): one product a bin, formed afresh every kReseed bins
    // (the others' poles lie half a partial spacing or more away, where 1 - z u_k is not small).
    constexpr std::size_t kReseed = 64;
    const Complex turn = std::polar(1.0, -2.0 * pi / static_cast<double>(length_));
    for (const DampedPartial& o : others)
        for (const auto& [kernel, amplitude] : {std::pair{PoleKernel(o.decay, o.angle, length_), o.amplitude},
                                                std::pair{PoleKernel(o.decay, -o.angle, length_), std::conj(o.amplitude)}}) {
            Complex zu;
            for (std::size_t i = 0; i < out.size(); ++i) {
                zu = i % kReseed == 0 ? 1.0 - kernel.step(first + i) : zu * turn;
                out[i] -= amplitude * kernel.value(1.0 - zu);
            }
        }
    return out;
}

double DecaySpectrum::residual_with(std::size_t first, std::span<const std::complex<double>> bins,
                                    std::span<const DampedPartial> poles) const {
    return solve(first, bins, poles, false).residual;
}

SpectrumFit DecaySpectrum::fit(std::size_t first, std::span<const std::complex<double>> bins,
                               std::span<const DampedPartial> start) const {
    return solve(first, bins, start, true);
}

SpectrumFit DecaySpectrum::solve(std::size_t first, std::span<const std::complex<double>> bins,
                                 std::span<const DampedPartial> start, bool move_poles) const {
    SpectrumFit out;
    out.residual = std::numeric_limits<double>::infinity();
    const int partials = static_cast<int>(start.size());
    const auto m = static_cast<Eigen::Index>(bins.size());
    const std::size_t last = first + bins.size() - 1;
    const int parameters = partials * kPerPartial + kBackground;
    if (2 * m <= parameters + 4) return out;
    const Eigen::VectorXcd data = Eigen::Map<const Eigen::VectorXcd>(bins.data(), m);
    double scale = 0.0;
    for (const DampedPartial& p : start) scale = std::max(scale, std::abs(p.amplitude));
    if (!(scale > 0.0)) scale = data.cwiseAbs().maxCoeff() / static_cast<double>(length_);
    if (!(scale > 0.0)) return out;
    Residuals residuals(*this, first, data, partials, scale);

    // The poles as given; amplitudes and background by linear least squares for them.
    Eigen::VectorXd x = Eigen::VectorXd::Zero(parameters);
    for (int p = 0; p < partials; ++p) {
        x(kPerPartial * p) = start[static_cast<std::size_t>(p)].decay * static_cast<double>(length_);
        x(kPerPartial * p + 1) = start[static_cast<std::size_t>(p)].angle * static_cast<double>(length_) / (2.0 * pi);
    }
    {
        Eigen::MatrixXd jacobian;
        residuals.df(x, jacobian);
        Eigen::VectorXd f(2 * m);
        residuals(x, f);  // with zero amplitudes and background: -data
        std::vector<Eigen::Index> linear;
        for (int p = 0; p < partials; ++p) linear.insert(linear.end(), {kPerPartial * p + 2, kPerPartial * p + 3});
        for (int b = 0; b < kBackground; ++b) linear.push_back(kPerPartial * partials + b);
        Eigen::MatrixXd a(2 * m, static_cast<Eigen::Index>(linear.size()));
        for (std::size_t j = 0; j < linear.size(); ++j) a.col(static_cast<Eigen::Index>(j)) = jacobian.col(linear[j]);
        const Eigen::VectorXd solution = a.colPivHouseholderQr().solve(-f);
        for (std::size_t j = 0; j < linear.size(); ++j) x(linear[j]) = solution(static_cast<Eigen::Index>(j));
        if (!move_poles) {
            out.residual = (f + a * solution).squaredNorm();
            return out;
        }
    }

    Eigen::LevenbergMarquardt<Residuals> lm(residuals);
    lm.setMaxfev(kEvaluations);
    lm.setXtol(1e-10);
    lm.setFtol(1e-10);
    const auto status = lm.minimize(x);
    if (status == Eigen::LevenbergMarquardtSpace::ImproperInputParameters) return out;

    Eigen::VectorXd f(2 * m);
    residuals(x, f);
    Eigen::MatrixXd jacobian;
    residuals.df(x, jacobian);
    out.bins = static_cast<std::size_t>(m);
    out.residual = f.squaredNorm();
    // Real and imaginary parts of a bin's noise each carry half its variance; the residual
    // has 2m - parameters degrees of freedom.
    out.noise_per_bin = std::max(2.0 * out.residual / static_cast<double>(2 * m - parameters), floor_per_bin_);
    const Eigen::MatrixXd fisher = jacobian.transpose() * jacobian;
    const Eigen::MatrixXd covariance =
        0.5 * out.noise_per_bin * fisher.completeOrthogonalDecomposition().pseudoInverse();
    bool inside = true;
    for (int p = 0; p < partials; ++p) {
        DampedPartial d;
        d.decay = residuals.to_decay(x(kPerPartial * p));
        d.angle = residuals.to_angle(x(kPerPartial * p + 1));
        d.amplitude = scale * Complex(x(kPerPartial * p + 2), x(kPerPartial * p + 3));
        d.decay_sd = std::sqrt(std::max(0.0, covariance(kPerPartial * p, kPerPartial * p))) / static_cast<double>(length_);
        d.angle_sd = residuals.to_angle(std::sqrt(std::max(0.0, covariance(kPerPartial * p + 1, kPerPartial * p + 1))));
        const double bin = x(kPerPartial * p + 1);
        inside = inside && d.decay > 0.0 && bin >= static_cast<double>(first) && bin <= static_cast<double>(last) &&
                 std::isfinite(d.decay_sd) && std::isfinite(d.angle_sd);
        out.partials.push_back(d);
    }
    if (partials == 2) {
        const double v = covariance(1, 1) + covariance(kPerPartial + 1, kPerPartial + 1) - 2.0 * covariance(1, kPerPartial + 1);
        out.angle_difference_sd = residuals.to_angle(std::sqrt(std::max(0.0, v)));
    }
    out.valid = inside && std::isfinite(out.residual);
    return out;
}

}  // namespace fretbuzz
