// The Siconos tutorials' Music example as fretbuzz runs it (cases/bass-music-frets.toml: its
// 20 frets as grid points, Newton's impact law, at the example's own 15.68 kHz and above):
// the energy kept to round-off through its elastic impacts, and the first contact where the
// free string, in closed form from the example's modes and initial state, first reaches a fret.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <numbers>
#include <vector>

#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/scheme/NewtonImpact.hpp"
#include "fretbuzz/scheme/Stepper.hpp"

namespace fretbuzz {
namespace {

Case music_case(double fs, double duration, double restitution) {
    Case c = load_case("bass-music-frets");
    c.run.sample_rate_hz = fs;
    c.run.allow_aliasing = true;  // the example's own coarse rates (modes above fs/2)
    c.run.duration_s = duration;
    c.contact.restitution = restitution;
    return c;
}

TEST(MusicReference, ElasticImpactsOnTheExampleNeckKeepTheEnergyToRoundOff) {
    // e = 1, lossless, over the pop's first 0.1 s: the burst of slaps on the frets.
    for (const double fs : {15680.0, 1003520.0}) {
        Case c = music_case(fs, 0.1, 1.0);
        c.make_lossless();
        const Plan plan(c, 1.0 / fs);
        NewtonImpact string(plan, c.initial_displacement, c.initial_velocity);
        string.step();
        const double h0 = string.energy();
        double worst = 0.0;
        const auto steps = static_cast<long>(std::lround(0.1 * fs));
        for (long n = 1; n < steps; ++n) {
            string.step();
            worst = std::max(worst, std::abs(string.energy() + string.dissipated() - h0) / h0);
        }
        std::cout << "Fe = " << fs << " Hz, e = 1, lossless: " << string.contact_steps()
                  << " impact steps, worst balance " << worst << ", impact loss " << string.impact_loss() / h0
                  << " of H\n";
        EXPECT_GT(string.contact_steps(), 50) << "the pop must slap the frets";
        EXPECT_LT(worst, 1e-12) << fs;
        EXPECT_LT(std::abs(string.impact_loss()) / h0, 1e-12) << fs;
    }
}

TEST(MusicReference, InelasticImpactsAtTheExampleRateLoseEnergyAtEveryStep) {
    // 15.68 kHz (modes above fs/2), e = 0 and 0.5, over the first 0.1 s: every step's impact term
    // is a loss to round-off, H never rises above H^{1/2} (lossless, any gain would show there),
    // and the balance closes. Some impulses here fall on points that moved away from the fret
    // over the step before (32 of 523 in the first 0.05 s at e = 0); the law with e there gained
    // up to 9 H(0) in one step (lossless, e = 0).
    for (const bool lossless : {true, false}) {
        for (const double e : {0.0, 0.5}) {
            Case c = music_case(15680.0, 0.1, e);
            if (lossless) c.make_lossless();
            const Plan plan(c, 1.0 / 15680.0);
            NewtonImpact string(plan, c.initial_displacement, c.initial_velocity);
            string.step();
            const double h0 = string.energy();
            double worst_step = 0.0, highest = 0.0, worst_balance = 0.0;
            for (long n = 1; n < 1568; ++n) {
                const double loss_before = string.impact_loss();
                string.step();
                worst_step = std::min(worst_step, (string.impact_loss() - loss_before) / h0);
                highest = std::max(highest, string.energy() / h0);
                worst_balance = std::max(worst_balance, std::abs(string.energy() + string.dissipated() - h0) / h0);
            }
            std::cout << (lossless ? "lossless" : "damped") << ", e = " << e << ": " << string.contact_steps()
                      << " impact steps, impact loss " << string.impact_loss() / h0 << " of H, lowest step "
                      << worst_step << ", highest H " << highest << ", worst balance " << worst_balance << "\n";
            EXPECT_GT(string.contact_steps(), 50) << "the pop must slap the frets";
            EXPECT_GE(worst_step, -1e-14) << "e = " << e << (lossless ? ", lossless" : "");
            EXPECT_LE(highest, 1.0 + 1e-13) << "e = " << e << (lossless ? ", lossless" : "");
            EXPECT_LT(worst_balance, 1e-12) << "e = " << e << (lossless ? ", lossless" : "");
            EXPECT_GT(string.impact_loss() / h0, 1e-3) << "e = " << e << (lossless ? ", lossless" : "");
        }
    }
}

// The first time t at which the free (contact-free) string reaches one of the case's points.
double free_first_contact(const Case& c) {
    const double L = c.string.length_m;
    const std::size_t modes = c.mode_count();
    std::vector<std::vector<double>> rows;  // phi_j at each point
    for (const PointObstacle& p : c.point_obstacles) {
        auto& row = rows.emplace_back(modes);
        for (std::size_t j = 0; j < modes; ++j)
            row[j] = std::sqrt(2.0 / L) * std::sin(static_cast<double>(j + 1) * std::numbers::pi * p.x_m / L);
    }
    auto gap = [&](double t) {  // min over the points of u(x, t) - g
        std::vector<double> q(modes);
        for (std::size_t j = 0; j < modes; ++j) {
            const double sigma = c.modes.sigma_per_s[j];
            const double omega = 2.0 * std::numbers::pi * c.modes.frequency_hz[j];
            const double wd = std::sqrt(omega * omega - sigma * sigma);
            q[j] = c.initial_displacement[j] * std::exp(-sigma * t) *
                   (std::cos(wd * t) + sigma / wd * std::sin(wd * t));
        }
        double worst = std::numeric_limits<double>::infinity();
        for (std::size_t k = 0; k < rows.size(); ++k) {
            double u = 0.0;
            for (std::size_t j = 0; j < modes; ++j) u += q[j] * rows[k][j];
            worst = std::min(worst, u - c.point_obstacles[k].height_m);
        }
        return worst;
    };
    // March in 1 us steps, then bisect the crossing to 1 ns.
    double t0 = 0.0;
    while (gap(t0 + 1e-6) > 0.0) t0 += 1e-6;
    double t1 = t0 + 1e-6;
    while (t1 - t0 > 1e-9) {
        const double mid = 0.5 * (t0 + t1);
        (gap(mid) > 0.0 ? t0 : t1) = mid;
    }
    return t1;
}

TEST(MusicReference, FirstContactIsWhereTheFreeStringFirstReachesAFret) {
    const Case c = music_case(15680.0, 0.006, 0.0);
    ASSERT_EQ(c.point_obstacles.size(), 20u);
    const double t_free = free_first_contact(c);
    std::cout << "free string reaches a fret at " << t_free * 1e3 << " ms\n";
    // Before any contact the exact scheme is the free string; a contact is seen at the end of
    // the step within which it begins (1 ns: the bisection's tolerance).
    for (const double fs : {15680.0, 250880.0, 4014080.0}) {
        const RunSummary s = simulate(music_case(fs, 0.006, 0.0), {});
        std::cout << "Fe = " << fs << " Hz: first contact " << s.first_contact_s * 1e3 << " ms\n";
        EXPECT_GE(s.first_contact_s, t_free - 1e-9) << fs;
        EXPECT_LE(s.first_contact_s, t_free + 1.0 / fs + 1e-9) << fs;
    }
}

}  // namespace
}  // namespace fretbuzz
