// The pickup's high-pass allocates nothing per sample (it may sit on an audio thread).
#include <gtest/gtest.h>

#include <cmath>

#include "AllocationCounter.hpp"
#include "fretbuzz/output/PickupHighPass.hpp"

namespace fretbuzz {
namespace {

TEST(PickupHighPass, AllocatesNothingPerSample) {
    PickupHighPass pickup(48000.0);
    double sum = 0.0;
    const long before = testing::allocations();
    {
        testing::Counting counting;
        for (int k = 0; k < 480000; ++k) sum += pickup(0.1 + std::sin(0.01 * k));
    }
    EXPECT_EQ(testing::allocations() - before, 0);
    EXPECT_TRUE(std::isfinite(sum));
}

}  // namespace
}  // namespace fretbuzz
