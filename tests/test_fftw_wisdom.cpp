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
#include "fretbuzz/scheme/SineTransform.hpp"

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
    std::vector<double> buffer(n);
    fftw_forget_wisdom();
    const unsigned flags = FFTW_MEASURE | FFTW_WISDOM_ONLY;
    EXPECT_EQ(fftw_plan_r2r_1d(n, buffer.data(), buffer.data(), FFTW_RODFT00, flags), nullptr);
    ASSERT_NE(fftw_import_wisdom_from_filename(path.c_str()), 0);
    fftw_plan plan = fftw_plan_r2r_1d(n, buffer.data(), buffer.data(), FFTW_RODFT00, flags);
    EXPECT_NE(plan, nullptr);
    if (plan != nullptr) fftw_destroy_plan(plan);
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
