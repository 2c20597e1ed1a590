// Buzz metrics on cases with known answers: the obstacle's features, Parseval for the
// high-frequency energy, an obstacle never touched, and a point obstacle that only the
// notes above a given fret reach (closed form of the ideal plucked string).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <sstream>

#include "SweepTestCases.hpp"
#include "TestSupport.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/analysis/BuzzMetrics.hpp"
#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/sweep/Sweep.hpp"

namespace fretbuzz {
namespace {

constexpr double inf = std::numeric_limits<double>::infinity();

TEST(BuzzMetrics, FeaturesAreThePeaksOfTheObstacleNumberedFromTheNut) {
    // A board sloping down towards the bridge with two frets (the second two points wide).
    const std::vector<double> g = {-1.0, -1.1, -0.5, -1.2, -1.3, -0.6, -0.6, -1.4, -1.5};
    const std::vector<std::size_t> f = obstacle_features(g);
    EXPECT_EQ(f, (std::vector<std::size_t>{1, 1, 1, 1, 2, 2, 2, 2, 2}));
    const std::vector<double> point = {-inf, -inf, -0.1, -inf};
    EXPECT_EQ(obstacle_features(point), (std::vector<std::size_t>{1, 1, 1, 1}));
    const std::vector<double> flat(5, -0.2);
    EXPECT_EQ(obstacle_features(flat), (std::vector<std::size_t>(5, 0)));
}

TEST(BuzzMetrics, HighFrequencyEnergyObeysParseval) {
    const double rate = 48000.0;
    std::vector<double> u(4800);
    for (std::size_t i = 0; i < u.size(); ++i) {
        const double t = static_cast<double>(i) / rate;
        u[i] = std::sin(2 * std::numbers::pi * 100.0 * t) + 0.01 * std::sin(2 * std::numbers::pi * 5000.0 * t);
    }
    double windowed = 0.0, high = 0.0;
    for (std::size_t i = 0; i < u.size(); ++i) {
        const double w = 0.5 * (1.0 - std::cos(2 * std::numbers::pi * static_cast<double>(i) / 4800.0));
        windowed += w * w * u[i] * u[i];
        const double t = static_cast<double>(i) / rate;
        const double hf = 0.01 * std::sin(2 * std::numbers::pi * 5000.0 * t);
        high += w * w * hf * hf;
    }
    EXPECT_NEAR(high_frequency_energy(u, rate, 0.0), windowed, 1e-12 * windowed);
    EXPECT_NEAR(high_frequency_energy(u, rate, 2000.0), high, 1e-6 * high);
    EXPECT_TRUE(std::isnan(high_frequency_energy(u, rate, 24000.0)));
}

Case note_case(double obstacle_height) {
    std::string text = testing::note_case_text();
    const std::string from = "height = -0.05e-3";
    std::ostringstream to;
    to.precision(17);
    to << "height = " << obstacle_height;
    text.replace(text.find(from), from.size(), to.str());
    return parse_case(text, "note.toml", DataSource::builtin());
}

TEST(BuzzMetrics, AnObstacleNeverTouchedReportsZero) {
    const Case c = note_case(-0.5e-3);  // the string reaches 0.1 mm below rest at x = 0.6 m
    BuzzMetrics metrics;
    RunObserver* observers[] = {&metrics};
    simulate(c, observers);
    const BuzzReport& b = metrics.report();
    EXPECT_EQ(b.contact_steps, 0);
    EXPECT_EQ(b.episodes, 0);
    EXPECT_EQ(b.touched_points, 0u);
    EXPECT_TRUE(b.touched_features.empty());
    EXPECT_EQ(b.main_feature, 0u);
    EXPECT_EQ(b.contact_time_s, 0.0);
    EXPECT_EQ(b.peak_force_n, 0.0);
    EXPECT_EQ(b.impulse_n_s, 0.0);
    EXPECT_EQ(b.energy_lost_in_contact_j, 0.0);
    EXPECT_TRUE(std::isnan(b.first_contact_s));
    EXPECT_GT(b.high_frequency_energy, 0.0);
}

TEST(BuzzMetrics, TouchedPointIsTheObstacleAndEpisodesAreSeparate) {
    const Case c = note_case(-0.05e-3);
    BuzzMetrics metrics(2000.0, 0.5e-3);
    RunObserver* observers[] = {&metrics};
    const RunSummary s = simulate(c, observers);
    const BuzzReport& b = metrics.report();
    EXPECT_EQ(b.contact_steps, s.contact_steps);
    EXPECT_EQ(b.first_contact_s, s.first_contact_s);
    EXPECT_EQ(b.last_contact_s, s.last_contact_s);
    EXPECT_EQ(b.touched_points, 1u);
    EXPECT_NEAR(b.touched_x_min_m, 0.6, c.grid_step());
    EXPECT_EQ(b.touched_features, (std::vector<std::size_t>{1}));
    EXPECT_EQ(b.main_feature, 1u);
    // The string comes down on the obstacle once per period (f1 = 269 Hz, 3.7 ms), near
    // t = T/2, 3T/2, 5T/2, bouncing on it each time (bounces, 0.3 ms apart at most, are
    // closer than the 0.5 ms episode gap and belong to one episode; the comings-down are
    // about 1 ms apart): three episodes in 10 ms.
    EXPECT_EQ(b.episodes, 3);
    EXPECT_GT(b.peak_force_n, 0.0);
    EXPECT_NEAR(b.contact_time_s, static_cast<double>(b.contact_steps) / c.run.sample_rate_hz, 1e-15);
}

// Notes played at frets n = 0..7 as strings of length L_n = S 2^(-n/12) (an ideal stop
// at the fret), plucked p = 0.15 m from the bridge, with a point obstacle d = 0.05 m from
// the bridge. The ideal string's lowest excursion there is A d / (L_n - p) (d'Alembert:
// u(x, T/2) = -u0(L - x)), growing with n: an obstacle set between the excursions of
// notes k and k+1 is touched by exactly the notes above fret k.
TEST(BuzzMetrics, APointObstacleIsTouchedOnlyByNotesAboveFretK) {
    const testing::ScratchDir dir("buzz-notes");
    testing::write_text(dir.path() / "note.toml", testing::note_case_text());
    const double S = 0.65, A = 1e-3, p = 0.15, d = 0.05;
    const int k = 3;
    auto length = [&](int n) { return S * std::pow(2.0, -n / 12.0); };
    auto reach = [&](int n) { return A * d / (length(n) - p); };
    const double g = -0.5 * (reach(k) + reach(k + 1));
    std::ostringstream spec;
    spec.precision(17);
    spec << "[sweep]\ncase = \"note.toml\"\ncombine = \"zip\"\n[set]\n\"obstacle.height\" = " << g << "\n";
    std::ostringstream L, x, pluck, observe;
    for (int n = 0; n <= 7; ++n) {
        const char* sep = n == 0 ? "" : ", ";
        L << sep << length(n);
        x << sep << "[" << length(n) - d << "]";
        pluck << sep << length(n) - p;
        observe << sep << "[" << length(n) - 0.1 << "]";
    }
    spec << "[[parameter]]\nkey = \"string.L\"\nvalues = [" << L.str() << "]\n";
    spec << "[[parameter]]\nkey = \"obstacle.x\"\nvalues = [" << x.str() << "]\n";
    spec << "[[parameter]]\nkey = \"excitation.position\"\nvalues = [" << pluck.str() << "]\n";
    spec << "[[parameter]]\nkey = \"observe.x\"\nvalues = [" << observe.str() << "]\n";
    testing::write_text(dir.path() / "spec.toml", spec.str());
    const SweepSpec sweep = load_sweep(dir.path() / "spec.toml");
    ASSERT_EQ(sweep.runs.size(), 8u);
    const auto& names = sweep_metric_names();
    const auto column = [&](const std::string& name) {
        return static_cast<std::size_t>(std::find(names.begin(), names.end(), name) - names.begin());
    };
    for (int n = 0; n <= 7; ++n) {
        const SweepRow row = run_sweep_point(sweep, static_cast<std::size_t>(n));
        ASSERT_TRUE(row.ok) << row.error;
        const bool touched = row.metrics[column("contact_steps")] > 0.0;
        EXPECT_EQ(touched, n > k) << "fret " << n;
        EXPECT_EQ(row.features, n > k ? "1" : "") << "fret " << n;
        // Untouched, the run is the obstacle-free run: the buzz band unchanged (0 dB) and
        // no contact-generated signal (no buzz level); touched, a contact-generated one.
        if (!touched) {
            EXPECT_NEAR(row.metrics[column("hf_change_dB")], 0.0, 1e-9) << "fret " << n;
            EXPECT_EQ(row.metrics[column("hf_energy_contact_m2")], 0.0) << "fret " << n;
            EXPECT_TRUE(std::isnan(row.metrics[column("buzz_dB")])) << "fret " << n;
        } else {
            EXPECT_GT(row.metrics[column("hf_energy_contact_m2")], 0.0) << "fret " << n;
            EXPECT_TRUE(std::isfinite(row.metrics[column("buzz_dB")])) << "fret " << n;
        }
    }
}

TEST(BuzzMetrics, EnergyLostInContactIsPartOfTheDissipatedEnergy) {
    Case c = load_case("bass-pop");
    c.run.duration_s = 0.01;
    BuzzMetrics metrics;
    RunObserver* observers[] = {&metrics};
    const RunSummary s = simulate(c, observers);
    const BuzzReport& b = metrics.report();
    EXPECT_GT(b.energy_lost_in_contact_j, 0.0);
    EXPECT_LE(b.energy_lost_in_contact_j, s.dissipated_j);
    EXPECT_GE(b.touched_features.size(), 2u);  // the pop slaps several frets
}

}  // namespace
}  // namespace fretbuzz
