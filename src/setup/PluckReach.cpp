#include "fretbuzz/setup/PluckReach.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fretbuzz {

double reach_margin(const StringNeck& neck, std::size_t k, double pluck_from_bridge_m) {
    const double length = neck.length() - neck.fret_x(k);
    const double p = std::clamp(length - pluck_from_bridge_m, 0.01 * length, 0.99 * length);
    const auto triangle = [&](double s) { return s <= p ? s / p : (length - s) / (length - p); };
    double margin = std::numeric_limits<double>::infinity();
    for (std::size_t n = k + 1; n <= neck.fret_count(); ++n) {
        const double s = neck.fret_x(n) - neck.fret_x(k);
        const double excursion = std::max(triangle(s), triangle(length - s));
        const double g = neck.clearance(k, n);
        if (g <= 0.0) return g;
        margin = std::min(margin, g / excursion);
    }
    return margin;
}

double predicted_clean_up_to(double clean_up_to, double cap, const StringNeck& before, const StringNeck& after,
                             std::size_t k, double pluck_from_bridge_m) {
    const double was = reach_margin(before, k, pluck_from_bridge_m);
    const double now = reach_margin(after, k, pluck_from_bridge_m);
    if (!(now > 0.0)) return 0.0;
    if (std::isinf(now) || !(was > 0.0)) return std::isinf(now) ? std::numeric_limits<double>::infinity() : 0.0;
    const double c = std::isinf(clean_up_to) ? cap : clean_up_to;
    return c * now / was;
}

}  // namespace fretbuzz
