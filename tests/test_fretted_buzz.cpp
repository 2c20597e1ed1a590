// Buzz metrics of fretted notes: the finger's pad and the fret it stops the string on are the
// fretting, not buzz; a fretted note that touches nothing beyond its fret reports no contact
// although the fret carries the finger's load all along, and its reference keeps the finger
// and the stopping fret and loses every fret beyond.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "SweepTestCases.hpp"
#include "TestSupport.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/analysis/BuzzMetrics.hpp"
#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/sweep/Sweep.hpp"

namespace fretbuzz {
namespace {

using testing::ScratchDir;
using testing::write_text;

// bass-neck on a 4 mm grid at 400 kHz, 20 ms, with `fret = 5` and the given excitation.
std::string fretted_neck(const std::string& excitation) {
    std::string text = "fret = 5\n" + builtin_case_text("bass-neck");
    const auto replace = [&](const std::string& from, const std::string& to) {
        text.replace(text.find(from), from.size(), to);
    };
    replace("modes = 862", "modes = 215");
    replace("fs = 4e6", "fs = 400000");
    replace("duration = 0.5", "duration = 0.02");
    const std::size_t begin = text.find("[excitation]"), end = text.find("[contact]");
    text.replace(begin, end - begin, "[excitation]\n" + excitation + "\n");
    return text;
}

TEST(FrettedBuzz, TheFrettingIsNotBuzzAndTheReferenceKeepsTheStoppingFret) {
    const Case c = parse_case(fretted_neck("type = \"sine\"\nmode = 1\namplitude = 0.0"), "neck.toml",
                              DataSource::builtin());
    const std::vector<std::size_t> feature = obstacle_features(c.obstacle_on_grid());
    const std::size_t first = first_buzz_point(c);
    // The first counted point is the first of fret 6's feature, between frets 5 and 6.
    EXPECT_EQ(feature[first], 6u);
    EXPECT_EQ(feature[first - 1], 5u);
    EXPECT_GT(c.grid_point(first), c.fret_positions_m[4]);
    EXPECT_LT(c.grid_point(first), c.fret_positions_m[5]);
    // Without fingers every contact counts.
    Case open = c;
    open.fingers.clear();
    EXPECT_EQ(first_buzz_point(open), 0u);
}

TEST(FrettedBuzz, AFrettedNoteThatTouchesNothingBeyondItsFretReportsNoContact) {
    // The string at rest on fret 5's top (a triangle with its apex there, 2 um above it: the sine
    // series of the triangle overshoots by about 1 um at the crown's exact x, off the grid), so
    // the finger lands on a string already on the fret: nothing but the fretting ever touches.
    const Case probe = parse_case(fretted_neck("type = \"sine\"\nmode = 1\namplitude = 0.0"), "neck.toml",
                                  DataSource::builtin());
    const std::size_t at5 = static_cast<std::size_t>(std::lround(probe.fret_positions_m[4] / probe.grid_step())) - 1;
    char shape[160];
    std::snprintf(shape, sizeof shape, "type = \"triangle\"\nposition = %.17g\namplitude = %.17g",
                  probe.grid_point(at5), probe.obstacle_on_grid()[at5] + 2e-6);
    ScratchDir dir("fretted-buzz");
    write_text(dir.path() / "neck.toml", fretted_neck(shape));
    write_text(dir.path() / "spec.toml", "[sweep]\ncase = \"neck.toml\"\n[[parameter]]\nkey = \"contact.alpha\"\n"
                                         "values = [1.5]\n");
    const SweepSpec spec = load_sweep(dir.path() / "spec.toml");
    // The run itself is in contact all along (the finger, the fret under it) ...
    const RunSummary summary = simulate(sweep_case(spec, spec.runs[0]), {});
    EXPECT_GE(summary.first_contact_s, 0.0);
    // ... but no buzz: no contact step, no touched fret, no buzz level.
    const SweepRow row = run_sweep_point(spec, 0);
    ASSERT_TRUE(row.ok) << row.error;
    const auto& names = sweep_metric_names();
    const auto metric = [&](const std::string& name) {
        return row.metrics[static_cast<std::size_t>(std::find(names.begin(), names.end(), name) - names.begin())];
    };
    EXPECT_EQ(metric("contact_steps"), 0.0);
    EXPECT_EQ(metric("touched_points"), 0.0);
    EXPECT_EQ(metric("peak_contact_force_N"), 0.0);
    EXPECT_TRUE(std::isnan(metric("buzz_dB")));
    EXPECT_EQ(row.features, "");
    // The reference: the same obstacle up to the stopping fret's feature, nothing beyond.
    const Case c = sweep_case(spec, spec.runs[0]);
    const Case reference = obstacle_free_case(spec, spec.runs[0]);
    const std::size_t first = first_buzz_point(c);
    for (std::size_t i = 0; i < c.obstacle_height_m.size(); ++i) {
        if (i < first)
            EXPECT_EQ(reference.obstacle_height_m[i], c.obstacle_height_m[i]) << i;
        else
            EXPECT_EQ(reference.obstacle_height_m[i], -std::numeric_limits<double>::infinity()) << i;
    }
    EXPECT_EQ(reference.fingers.size(), 1u);
}

}  // namespace
}  // namespace fretbuzz
