// The pad points' scalar root (fingers, pluckers): Newton inside a bracket, ended where h
// reaches its round-off, or where a Newton step of a few ulps no longer halves h (h then
// sits at the round-off of a term the caller's scale does not see; the engine's fuzzed events
// met one in a finger's pad point). That second end must not cut a steep solve short.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "../src/numerics/MonotoneRoot.hpp"

namespace fretbuzz {
namespace {

TEST(MonotoneRoot, FindsTheRootOfASteepContactLawToRoundOff) {
    // h(x) = x - w + k [x - g]_+^2: a penalty law, steep beyond g, with a closed-form root.
    const double w = 1e-3, k = 1e9;
    for (const double g : {0.0, 2e-4, 9e-4}) {
        double last = 0.0;
        const auto evaluate = [&](double x) {
            last = x;
            const double pen = x > g ? x - g : 0.0;
            return detail::MonotoneValue{x - w + k * pen * pen, std::abs(x) + std::abs(w) + k * pen * pen,
                                         1.0 + 2.0 * k * pen};
        };
        ASSERT_GE(detail::monotone_root(evaluate, -1e-3, 100), 0) << "g = " << g;
        // k p^2 + p - (w - g) = 0 for p = x - g > 0.
        const double p = 2.0 * (w - g) / (1.0 + std::sqrt(1.0 + 4.0 * k * (w - g)));
        EXPECT_NEAR(last, g + p, 8.0 * std::numeric_limits<double>::epsilon() * (g + p)) << "g = " << g;
    }
}

}  // namespace
}  // namespace fretbuzz
