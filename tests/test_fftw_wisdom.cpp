// FFTW plans once per process for each transform length, and what its measuring planner
// learns is kept in a cache file that a later process reads back.
#include <fftw3.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <mutex>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "TestSupport.hpp"
#include "fretbuzz/numerics/SineTransform.hpp"

namespace fretbuzz {
namespace {

// Sets an environment variable for the scope of a test.
class ScopedEnvironment {
public:
    ScopedEnvironment(const char* name, const std::string& value) : name_(name) {
        if (const char* old = std::getenv(name)) old_ = old;
        ::setenv(name, value.c_str(), 1);
    }
    ~ScopedEnvironment() {
        if (old_)
            ::setenv(name_, old_->c_str(), 1);
        else
            ::unsetenv(name_);
    }

private:
    const char* name_;
    std::optional<std::string> old_;
};

TEST(FftwPlans, OnePlanPerLengthPerProcessAndTheSameTransform) {
    constexpr std::size_t n = 517;
    const std::size_t before = fftw_plans_made();
    const SineTransform first(n), second(n);
    EXPECT_EQ(fftw_plans_made(), before + 1);
    // Both compute the type-I sine transform: y_k = 2 sum_j x_j sin(pi (j+1)(k+1)/(n+1)).
    std::vector<double> x(n), a(n), b(n);
    for (std::size_t j = 0; j < n; ++j) x[j] = std::cos(0.37 * static_cast<double>(j * j % 101));
    first.apply(x, a, 1.0);
    second.apply(x, b, 1.0);
    EXPECT_EQ(a, b);
    for (std::size_t k : {0UL, 100UL, n - 1}) {
        double direct = 0.0;
        for (std::size_t j = 0; j < n; ++j)
            direct += 2.0 * x[j] * std::sin(std::numbers::pi * static_cast<double>((j + 1) * (k + 1)) / (n + 1.0));
        EXPECT_NEAR(a[k], direct, 1e-11 * static_cast<double>(n));
    }
}

TEST(FftwPlans, TheTransformIsAccurateToRoundOffAtEveryLength) {
    // Against the sum in long double: a few ulps of the result's norm, with N + 1 composite
    // (1000), prime (863) and small (120). A stepwise recurrence (the half-length real-DFT
    // algorithm) would be 10-20x less accurate and fail this.
    for (std::size_t n : {119UL, 862UL, 999UL}) {
        const SineTransform transform(n);
        std::vector<double> x(n), y(n);
        for (std::size_t j = 0; j < n; ++j) x[j] = std::sin(0.37 * static_cast<double>(j * j)) + 0.1;
        transform.apply(x, y, 0.5);
        long double error = 0.0L, norm = 0.0L;
        const long double pi = 3.141592653589793238462643383279502884L;
        for (std::size_t k = 0; k < n; ++k) {
            long double direct = 0.0L;
            for (std::size_t j = 0; j < n; ++j) {
                const std::size_t phase = (j + 1) * (k + 1) % (2 * (n + 1));  // exact argument
                direct += static_cast<long double>(x[j]) *
                          std::sin(pi * static_cast<long double>(phase) / static_cast<long double>(n + 1));
            }
            error += (static_cast<long double>(y[k]) - direct) * (static_cast<long double>(y[k]) - direct);
            norm += direct * direct;
        }
        EXPECT_LT(static_cast<double>(std::sqrt(error / norm)), 1e-15) << "n = " << n;
        // In place gives the same numbers.
        transform.apply(x, x, 0.5);
        EXPECT_EQ(x, y) << "n = " << n;
    }
}

TEST(FftwPlans, MeasuredWisdomIsKeptInTheCacheAndReadBack) {
    testing::ScratchDir scratch("wisdom");
    const ScopedEnvironment cache("XDG_CACHE_HOME", scratch.str());
    const std::filesystem::path path = fftw_wisdom_path();
    ASSERT_EQ(path, scratch.path() / "fretbuzz" / "fftw-wisdom");
    constexpr int n = 1234;
    { const SineTransform measured(n, true); }
    ASSERT_TRUE(std::filesystem::exists(path));
    // A process without the wisdom cannot plan from wisdom alone; with the file read back it can.
    std::lock_guard lock(fftw_planner_mutex());
    const int m = static_cast<int>(SineTransform::extended_length(n));  // the real DFT it runs
    double* in = fftw_alloc_real(static_cast<std::size_t>(m));
    fftw_complex* out = fftw_alloc_complex(static_cast<std::size_t>(m / 2 + 1));
    fftw_forget_wisdom();
    const unsigned flags = FFTW_MEASURE | FFTW_WISDOM_ONLY;
    EXPECT_EQ(fftw_plan_dft_r2c_1d(m, in, out, flags), nullptr);
    ASSERT_NE(fftw_import_wisdom_from_filename(path.c_str()), 0);
    fftw_plan plan = fftw_plan_dft_r2c_1d(m, in, out, flags);
    EXPECT_NE(plan, nullptr);
    if (plan != nullptr) fftw_destroy_plan(plan);
    fftw_free(in);
    fftw_free(out);
}

TEST(FftwPlans, AnUnwritableCacheIsHarmless) {
    const ScopedEnvironment cache("XDG_CACHE_HOME", "/proc/no-such-place");
    const SineTransform measured(1235, true);
    std::vector<double> x(1235, 1.0), y(1235);
    measured.apply(x, y, 1.0);
    EXPECT_TRUE(std::isfinite(y[0]));
}

}  // namespace
}  // namespace fretbuzz
