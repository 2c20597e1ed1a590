// One pass over the modes per step (PlanOptions::fused_step): the step also forms the next
// step's predicted heights at a few active points and the displacement at an observation row.
// It agrees with the pass-per-product path (fused_step = false) within the stated tolerance: the
// same states, energies and outputs at every step, through contacts, a strike between steps (the state changes at
// the same step index) and an observation row whose values change.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "Equivalence.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/Stepper.hpp"

namespace fretbuzz {
namespace {

using testing::agree;

void expect_fused_equals_separate(const std::string& name, long steps) {
    const Case c = load_case(name);
    const double dt = 1.0 / c.run.sample_rate_hz;
    PlanOptions separate_options;
    separate_options.fused_step = false;
    const Plan fused_plan(c, dt), separate_plan(c, dt, separate_options);
    const double length = c.string.length_m;
    std::vector<double> pickup = fused_plan.basis().mode_shapes_at(0.81 * length);
    Stepper fused(fused_plan, c.initial_displacement, c.initial_velocity);
    Stepper separate(separate_plan, c.initial_displacement, c.initial_velocity);
    fused.observe(pickup);
    separate.observe(pickup);
    fused.audit_every(3);  // the pass forms the energy at every third step
    // A strike: a velocity bump over a tenth of the string.
    const std::vector<double> none(c.mode_count(), 0.0);
    std::vector<double> bump(c.mode_count(), 0.0);
    for (std::size_t j = 0; j < bump.size(); j += 3) bump[j] = 1e-3 / static_cast<double>(j + 1);
    for (long n = 1; n <= steps; ++n) {
        fused.step();
        separate.step();
        const std::string where = name + " step " + std::to_string(n);
        ASSERT_TRUE(agree(fused.modal_displacement(), separate.modal_displacement())) << where;
        ASSERT_TRUE(agree(fused.modal_difference(), separate.modal_difference())) << where;
        ASSERT_TRUE(agree(fused.energy(), separate.energy())) << where;
        ASSERT_TRUE(agree(fused.dissipated(), separate.dissipated())) << where;
        ASSERT_TRUE(agree(fused.observation(), separate.displacement(pickup))) << where;
        ASSERT_TRUE(agree(separate.observation(), separate.displacement(pickup))) << where;
        if (n == steps / 3) {  // the state changes between two steps: nothing formed before may be used
            fused.perturb(none, bump);
            separate.perturb(none, bump);
            ASSERT_TRUE(agree(fused.observation(), separate.displacement(pickup))) << where << " (struck)";
        }
        if (n == 2 * steps / 3) {  // the row moves (a pickup moved between blocks)
            fused_plan.basis().mode_shapes_at(0.23 * length, pickup);
            fused.observe(pickup);
            separate.observe(pickup);
            ASSERT_TRUE(agree(fused.observation(), separate.displacement(pickup))) << where << " (moved)";
        }
    }
    EXPECT_GT(fused.statistics().contact_steps, 0) << name;  // the contact steps were compared
    EXPECT_EQ(fused.statistics().contact_steps, separate.statistics().contact_steps) << name;
}

// One point (the tanpura's bridge), four (the sitar's), points woken by screening (a pop
// against the frets, first contact after 15000 steps) and a finger's pad (no prediction
// formed ahead, the pickup still).
TEST(FusedStep, AgreesWithAPassPerProduct) {
    expect_fused_equals_separate("tanpura", 3000);
    expect_fused_equals_separate("sitar", 3000);
    expect_fused_equals_separate("bass-pop", 20000);
    expect_fused_equals_separate("bass-fret5-pop", 20000);
}

}  // namespace
}  // namespace fretbuzz
