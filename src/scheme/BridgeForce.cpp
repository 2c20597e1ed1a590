#include "fretbuzz/scheme/BridgeForce.hpp"

#include <cmath>
#include <numbers>

namespace fretbuzz {

std::vector<double> bridge_force_coefficients(const Case& c) {
    using std::numbers::pi;
    const double length = c.string.length_m;
    const double norm = std::sqrt(2.0 / length);
    std::vector<double> b(c.mode_count());
    for (std::size_t j = 1; j <= b.size(); ++j) {
        const double k = static_cast<double>(j) * pi / length;
        const double w = 2.0 * pi * c.modes.frequency_hz[j - 1];
        const double parity = j % 2 == 0 ? 1.0 : -1.0;  // cos(j pi) = (-1)^j
        b[j - 1] = -norm * parity * c.string.linear_density * w * w / k;
    }
    return b;
}

}  // namespace fretbuzz
