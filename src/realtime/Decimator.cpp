#include "fretbuzz/realtime/Decimator.hpp"

#include <cmath>
#include <complex>
#include <numbers>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/numerics/Kernels.hpp"

namespace fretbuzz {

namespace {
// Kaiser window shape: about 90 dB of stop-band attenuation.
constexpr double kKaiserBeta = 9.0;

double bessel_i0(double x) {
    double sum = 1.0, term = 1.0;
    for (int k = 1; k < 60; ++k) {
        term *= (x / (2.0 * k)) * (x / (2.0 * k));
        sum += term;
        if (term < 1e-17 * sum) break;
    }
    return sum;
}
}  // namespace

Decimator::Decimator(int factor, int taps_per_phase, double cutoff) : factor_(factor) {
    if (factor < 1) throw InputError(out_of_range_message("decimation factor", factor, ">= 1"));
    if (taps_per_phase < 1) throw InputError(out_of_range_message("taps per phase", taps_per_phase, ">= 1"));
    if (!(cutoff > 0.0 && cutoff < 0.5)) throw InputError(out_of_range_message("cutoff", cutoff, "(0, 0.5)"));
    if (factor == 1) {
        taps_ = {1.0};  // nothing to remove: the host rate is the step rate
    } else {
        const std::size_t length = static_cast<std::size_t>(factor) * static_cast<std::size_t>(taps_per_phase);
        taps_.resize(length);
        const double fc = cutoff / factor;  // fraction of the input rate
        const double middle = 0.5 * static_cast<double>(length - 1);
        double sum = 0.0;
        for (std::size_t n = 0; n < length; ++n) {
            const double t = static_cast<double>(n) - middle;
            const double sinc = t == 0.0 ? 2.0 * fc : std::sin(2.0 * std::numbers::pi * fc * t) / (std::numbers::pi * t);
            const double r = t / (middle + 0.5);
            const double window = bessel_i0(kKaiserBeta * std::sqrt(std::max(0.0, 1.0 - r * r))) / bessel_i0(kKaiserBeta);
            taps_[n] = sinc * window;
            sum += taps_[n];
        }
        for (double& h : taps_) h /= sum;  // unit gain at DC
    }
    history_.assign(2 * taps_.size(), 0.0);
}

double Decimator::output() const {
    // history_[position_ ..] holds the inputs from oldest to newest; the taps are symmetric.
    // The library's dot product (eight partial sums, AVX2 where the CPU has it): at M = 8 the
    // 512 taps are about a twentieth of a contact-heavy block's time in four scalar sums.
    return kernels::dot(taps_.data(), history_.data() + position_, taps_.size());
}

void Decimator::reset() {
    std::fill(history_.begin(), history_.end(), 0.0);
    position_ = 0;
}

double Decimator::gain_at(double f) const {
    std::complex<double> sum = 0.0;
    for (std::size_t n = 0; n < taps_.size(); ++n)
        sum += taps_[n] * std::polar(1.0, -2.0 * std::numbers::pi * f * static_cast<double>(n));
    return std::abs(sum);
}

}  // namespace fretbuzz
