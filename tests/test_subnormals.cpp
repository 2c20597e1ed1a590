// No arithmetic on subnormal numbers in the offline runs: as a string decays, its high modes
// sink below 2.2e-308, where many processors compute every product in microcode. The runs
// flush them to zero on whichever thread they run (SubnormalFlush); these tests look at the
// modal state a run leaves, which holds subnormals on every processor if the flush is missing,
// whatever that processor's speed on them.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <thread>

#include "TestSupport.hpp"
#include "fretbuzz/SubnormalFlush.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/StringsCaseFile.hpp"
#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/run/StringsRun.hpp"

namespace fretbuzz {
namespace {

// Formed at run time, so the compiler cannot fold the product.
double product(double a, double b) {
    volatile double x = a, y = b;
    return x * y;
}

bool flushing_supported() {
#if defined(__x86_64__) || defined(__SSE2__) || defined(__aarch64__)
    return true;
#else
    return false;
#endif
}

TEST(Subnormals, TheGuardFlushesWhileItLivesAndRestoresTheThreadsMode) {
    if (!flushing_supported()) GTEST_SKIP() << "this processor has no flush-to-zero mode";
    const double tiny = std::numeric_limits<double>::min();  // 2.2e-308, the smallest normal number
    ASSERT_FALSE(SubnormalFlush::active());
    EXPECT_EQ(std::fpclassify(product(tiny, 0.25)), FP_SUBNORMAL);
    {
        const SubnormalFlush flushed;
        EXPECT_TRUE(SubnormalFlush::active());
        EXPECT_EQ(product(tiny, 0.25), 0.0);
        {
            const SubnormalFlush nested;
            EXPECT_TRUE(SubnormalFlush::active());
        }
        EXPECT_TRUE(SubnormalFlush::active()) << "an inner guard must put back the outer one's mode";
    }
    EXPECT_FALSE(SubnormalFlush::active());
    EXPECT_EQ(std::fpclassify(product(tiny, 0.25)), FP_SUBNORMAL);
}

TEST(Subnormals, CountedFromTheirBitsEvenWhileInputsAreFlushed) {
    const double tiny = std::numeric_limits<double>::denorm_min();
    const double values[] = {0.0, -0.0, 1.0, std::numeric_limits<double>::min(), tiny, -tiny, 1e-310};
    EXPECT_EQ(subnormal_count(values), 3u);
    const SubnormalFlush flushed;  // a comparison with zero would now read them as zero
    EXPECT_EQ(subnormal_count(values), 3u);
}

RunSummary run_on_own_thread(const Case& c) {
    RunSummary summary;
    bool flushing_after = true;
    // A thread of its own, as a worker of the set-up bench or the Python interpreter's would be.
    std::thread worker([&] {
        summary = simulate(c, {});
        flushing_after = SubnormalFlush::active();
    });
    worker.join();
    EXPECT_FALSE(flushing_after) << "the run must give its thread back its own floating-point mode";
    return summary;
}

TEST(Subnormals, TheThreeSecondBassPopLeavesNoSubnormalCoordinate) {
    // The README's main job at the paper's 4 MHz: past 1-2 s the modes above about 100 kHz are
    // below 1e-308 (their damping is thousands per second).
    Case c = load_case("bass-pop");
    c.run.duration_s = 3.0;
    const RunSummary s = run_on_own_thread(c);
    EXPECT_EQ(s.subnormal_coordinates, 0u) << "of " << 2 * s.modes << " coordinates";
    EXPECT_LT(s.max_relative_balance_error, 1e-10);
}

TEST(Subnormals, ALongSitarDecayLeavesNoSubnormalCoordinate) {
    // The sitar rests on its bridge at every step: its contacts are solved all along, so
    // nothing flies past the decayed modes. 20 s at 48 kHz (its high modes are subnormal
    // from about 15 s on without the flush).
    Case c = load_case("sitar");
    c.run.duration_s = 20.0;
    const RunSummary s = run_on_own_thread(c);
    EXPECT_EQ(s.subnormal_coordinates, 0u) << "of " << 2 * s.modes << " coordinates";
}

TEST(Subnormals, StringsOnABridgeLeaveNoSubnormalCoordinate) {
    // Two strings on a bridge struck 1e-300 times as hard as the case's: their modes (and the
    // bridge's) reach the subnormal range within the run, as a struck string's would after a
    // long decay, without the minutes of stepping that takes.
    StringsCase sc = parse_strings_case(*read_strings_case_text("strings-on-a-bridge"));
    for (Case& c : sc.strings) {
        for (double& q : c.initial_displacement) q *= 1e-300;
        for (double& v : c.initial_velocity) v *= 1e-300;
    }
    sc.run.duration_s = 2.0;
    StringsRun run;
    std::thread worker([&] { run = simulate_strings(sc); });
    worker.join();
    EXPECT_EQ(run.subnormal_coordinates, 0u);
    EXPECT_LT(run.max_relative_balance_error, 1e-10);
}

}  // namespace
}  // namespace fretbuzz
