// A finger placed, pressed and lifted while the string runs (what the real-time engine does
// between blocks): the balance H - W + D stays constant to round-off across each event's own
// (counted) change, a pressed finger pushes on the string with the pressing force on average,
// and a lifted one leaves the string to the obstacle's own solve.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "SmallBass.hpp"

namespace fretbuzz {
namespace {

TEST(RuntimeFinger, PlacedPressedAndLiftedKeepsTheBalance) {
    Case c = testing::small_bass(100000.0, 1.0, 0.3e-3);
    FingerSpec idle = c.fret_finger(1, "runtime finger");
    idle.force_profile.clear();
    idle.default_force = false;
    c.fingers.push_back(idle);
    const Plan plan(c, 1.0 / c.run.sample_rate_hz);
    Stepper s(plan, c.initial_displacement, c.initial_velocity);
    const auto ledger = [&] { return s.energy() - s.work() + s.dissipated(); };
    s.step();
    double events = 0.0;  // the energy the events themselves change (counted, as the engine does)
    const auto event = [&](auto&& f) {
        const double before = ledger();
        f();
        events += ledger() - before;
    };
    event([&] { s.lift_finger(0); });
    EXPECT_FALSE(s.finger_on(0));
    const double start = ledger() - events;
    double worst = 0.0;
    const auto run = [&](long steps) {
        for (long n = 0; n < steps; ++n) {
            s.step();
            const double scale = std::max(std::abs(start), std::abs(s.work()));
            worst = std::max(worst, std::abs(ledger() - events - start) / scale);
        }
    };
    run(2000);
    const FingerSpec at5 = c.fret_finger(5, "fret");
    event([&] { ASSERT_TRUE(s.place_finger(0, at5.position_m, at5.width_m)); });
    s.press_finger(0, 5.0, 500);  // 5 N after 5 ms
    run(20000);
    EXPECT_TRUE(s.finger_on(0));
    EXPECT_GT(s.work(), 0.0);
    EXPECT_GT(s.finger_loss(), 0.0);
    // Held down, the finger's momentum barely changes: on average the string pushes back with
    // the pressing force.
    double mean = 0.0;
    for (int n = 0; n < 10000; ++n) {
        run(1);
        mean += s.fingers()[0].contact_force() / 10000.0;
    }
    EXPECT_NEAR(mean, 5.0, 0.05);
    s.press_finger(0, 0.0, 500);
    long waited = 0;
    while (waited < 20000 && (s.fingers()[0].acted() || s.fingers()[0].contact_energy() != 0.0 || waited < 500)) {
        run(1);
        ++waited;
    }
    EXPECT_LT(waited, 20000);  // the string threw the finger off
    event([&] { s.lift_finger(0); });
    run(5000);
    EXPECT_LT(worst, 1e-10);
}

}  // namespace
}  // namespace fretbuzz

namespace fretbuzz {
namespace {

// A copy of a stepper with a finger on the string plays its own finger: stepped alike, the copy
// and the original stay equal, and stepping one leaves the other's finger where it was.
TEST(RuntimeFinger, ACopiedStepperPlaysItsOwnFinger) {
    Case c = testing::small_bass(100000.0, 1.0, 0.3e-3);
    c.fingers.push_back(c.fret_finger(3, "finger"));
    const Plan plan(c, 1.0 / c.run.sample_rate_hz);
    Stepper a(plan, c.initial_displacement, c.initial_velocity);
    for (int n = 0; n < 300; ++n) a.step();
    ASSERT_TRUE(a.played());
    Stepper b = a;
    const double height = a.fingers()[0].height(), work = a.work();
    for (int n = 0; n < 300; ++n) b.step();
    EXPECT_EQ(a.fingers()[0].height(), height);  // the original's finger did not move
    EXPECT_EQ(a.work(), work);
    EXPECT_NE(b.fingers()[0].height(), height);
    for (int n = 0; n < 300; ++n) a.step();
    EXPECT_EQ(a.fingers()[0].height(), b.fingers()[0].height());
    EXPECT_EQ(a.energy(), b.energy());
    EXPECT_EQ(a.work(), b.work());
    for (std::size_t j = 0; j < c.mode_count(); ++j)
        ASSERT_EQ(a.modal_displacement()[j], b.modal_displacement()[j]) << j;
}

}  // namespace
}  // namespace fretbuzz
