#include "fretbuzz/output/PickupHighPass.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace fretbuzz {

PickupHighPass::PickupHighPass(double rate_hz, double corner_hz) {
    if (!(rate_hz > 0.0 && corner_hz > 0.0 && corner_hz < 0.5 * rate_hz))
        throw std::invalid_argument("PickupHighPass: a corner of " + std::to_string(corner_hz) + " Hz at " +
                                    std::to_string(rate_hz) + " Hz");
    // The bilinear transform of the analogue Butterworth section, prewarped at the corner.
    const double w = 2.0 * std::numbers::pi * corner_hz / rate_hz;
    const double alpha = std::sin(w) / std::numbers::sqrt2;  // sin(w) / (2 Q), Q = 1 / sqrt(2)
    const double c = std::cos(w);
    const double a0 = 1.0 + alpha;
    b0_ = 0.5 * (1.0 + c) / a0;
    b1_ = -(1.0 + c) / a0;
    b2_ = b0_;
    a1_ = -2.0 * c / a0;
    a2_ = (1.0 - alpha) / a0;
}

}  // namespace fretbuzz
