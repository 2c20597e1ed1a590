// Newton's impact law over the exact modal scheme (scheme/NewtonImpact.hpp): the energy kept to
// round-off through every impact at e = 1, the losses at e < 1 in the ledger, the loss of one
// impact against its closed form, the screened path against the straightforward one, and the
// penalty's limit as K grows on a point obstacle.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <iostream>
#include <limits>
#include <span>
#include <vector>

#include "SmallBass.hpp"
#include "TestSupport.hpp"

#include "fretbuzz/Error.hpp"
#include "fretbuzz/run/ResultRecorder.hpp"
#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/scheme/NewtonImpact.hpp"
#include "fretbuzz/scheme/Stepper.hpp"

namespace fretbuzz {
namespace {

Case impact_bass(double fs, double duration, double amplitude, double restitution) {
    Case c = testing::small_bass(fs, duration, amplitude);
    c.contact.law = ContactLawKind::impact;
    c.contact.restitution = restitution;
    return c;
}

struct Ledger {
    double worst_balance = 0.0;  // max |H + dissipated - H^{1/2}| / H^{1/2} over the steps
    double impact_loss = 0.0;
    long contact_steps = 0;
};

Ledger run_ledger(const Case& c, long steps) {
    const Plan plan(c, 1.0 / c.run.sample_rate_hz);
    NewtonImpact string(plan, c.initial_displacement, c.initial_velocity);
    string.step();
    const double h0 = string.energy();
    Ledger ledger;
    for (long n = 1; n < steps; ++n) {
        string.step();
        ledger.worst_balance =
            std::max(ledger.worst_balance, std::abs(string.energy() + string.dissipated() - h0) / h0);
    }
    ledger.impact_loss = string.impact_loss() / h0;
    ledger.contact_steps = string.contact_steps();
    return ledger;
}

TEST(NewtonImpact, ElasticImpactsKeepTheEnergyToRoundOff) {
    // A 2 mm pluck of the 255-mode bass, lossless, against its 20 frets and board, e = 1.
    Case c = impact_bass(400000.0, 0.05, 2e-3, 1.0);
    c.make_lossless();
    const Ledger ledger = run_ledger(c, 20000);
    std::cout << "e = 1, lossless: " << ledger.contact_steps << " impact steps, worst balance "
              << ledger.worst_balance << ", impact loss " << ledger.impact_loss << " of H\n";
    EXPECT_GT(ledger.contact_steps, 20);
    EXPECT_LT(ledger.worst_balance, 1e-12);
    EXPECT_LT(std::abs(ledger.impact_loss), 1e-12);
}

TEST(NewtonImpact, InelasticImpactsLoseWhatTheLedgerSays) {
    // e = 0.5 with the string's damping: the impacts take energy, and H + damping + impact
    // losses stays H^{1/2} to round-off.
    const Ledger ledger = run_ledger(impact_bass(400000.0, 0.05, 2e-3, 0.5), 20000);
    std::cout << "e = 0.5, damped: " << ledger.contact_steps << " impact steps, worst balance "
              << ledger.worst_balance << ", impact loss " << ledger.impact_loss << " of H\n";
    EXPECT_GT(ledger.contact_steps, 20);
    EXPECT_GT(ledger.impact_loss, 1e-3);
    EXPECT_LT(ledger.worst_balance, 1e-12);
}

// The 255-mode bass, lossless, with one obstacle at height 0: grid point 120, or an exact point
// at 0.41234 m; its position into x.
Case one_point_case(bool on_grid, double& x) {
    Case c = testing::small_bass(400000.0, 1e-3, 0.0);
    c.make_lossless();
    c.contact.law = ContactLawKind::impact;
    std::fill(c.obstacle_height_m.begin(), c.obstacle_height_m.end(), -std::numeric_limits<double>::infinity());
    x = on_grid ? c.grid_point(120) : 0.41234;
    c.point_obstacles.clear();  // (the frets)
    if (on_grid)
        c.obstacle_height_m[120] = 0.0;
    else
        c.point_obstacles = {{x, 0.0, c.grid_step()}};
    return c;
}

// (q^0, v0) from which the exact free first step of the lossless modes reaches q^1 with
// q^1 - q^0 = d^1: q(t) = q^0 cos(omega t) + v0 sin(omega t) / omega.
void start_reaching(const Case& c, double dt, std::span<const double> q1, std::span<const double> d1,
                    std::vector<double>& q0, std::vector<double>& v0) {
    q0.resize(q1.size());
    v0.resize(q1.size());
    for (std::size_t j = 0; j < q1.size(); ++j) {
        const double omega = 2.0 * M_PI * c.modes.frequency_hz[j];
        q0[j] = q1[j] - d1[j];
        v0[j] = omega * (q1[j] - q0[j] * std::cos(omega * dt)) / std::sin(omega * dt);
    }
}

// One impact on a single point from a state with q^1 = 0, so that the free step leaves the
// point's velocity as it was: the loss is then (1 - e^2) (mu / W) (u^- / dt)^2 / 2, with W the
// point's row . row (its effective mass mu / W).
void expect_one_impact_closed_form(bool on_grid) {
    double x = 0.0;
    Case c = one_point_case(on_grid, x);
    const std::size_t n = c.mode_count();
    const double dt = 1.0 / c.run.sample_rate_hz;
    for (double e : {0.0, 0.3, 0.8, 1.0}) {
        c.contact.restitution = e;
        const Plan plan(c, dt);
        ASSERT_EQ(plan.point_contact().size(), on_grid ? 0u : 1u);
        const std::vector<double> phi = plan.basis().mode_shapes_at(x);
        // d^1 = D (downward at x), q^1 = 0.
        std::vector<double> q1(n, 0.0), d1(n), q0, v0;
        double u_before = 0.0, w = 0.0;
        for (std::size_t j = 0; j < n; ++j) {
            d1[j] = -1e-7 * phi[j] * std::exp(-static_cast<double>(j) / 30.0);
            u_before += phi[j] * d1[j];
            w += phi[j] * phi[j];
        }
        start_reaching(c, dt, q1, d1, q0, v0);
        NewtonImpact string(plan, q0, v0);
        string.step();
        const double h = string.energy();
        string.step();
        ASSERT_TRUE(string.touched_obstacle());
        const double normal_kinetic = 0.5 * c.string.linear_density / w * (u_before / dt) * (u_before / dt);
        const double expected = (1.0 - e * e) * normal_kinetic;
        std::cout << (on_grid ? "grid" : "exact") << " point, e = " << e << ": loss " << string.impact_loss()
                  << " J, (1 - e^2) x normal kinetic energy " << expected << " J\n";
        EXPECT_NEAR(string.impact_loss(), expected, 1e-12 * normal_kinetic) << "e = " << e;
        EXPECT_NEAR(string.energy() + string.dissipated(), h, 1e-13 * h);
    }
}

// A point that moved up (away from the obstacle) over the first step, u^- > 0, and whose free
// second step reverses into the obstacle: it made no approach for e to act on, so the impulse
// does no work (u^+ = -u^-, the point back where it was at n = 0) whatever e. The law with e
// here would stop it at u^+ = -e u^- and gain lambda (1 - e) u^-.
void expect_a_point_moving_away_takes_no_energy(bool on_grid) {
    double x = 0.0;
    Case c = one_point_case(on_grid, x);
    const std::size_t n = c.mode_count();
    const double dt = 1.0 / c.run.sample_rate_hz;
    for (double e : {0.0, 0.5}) {
        c.contact.restitution = e;
        const Plan plan(c, dt);
        const std::vector<double> phi = plan.basis().mode_shapes_at(x);
        // Low modes displaced up at x and moving up: their restoring force reverses the point
        // within one step only if the displacement is large against the step's motion.
        std::vector<double> q1(n, 0.0), d1(n, 0.0), q0, v0;
        for (std::size_t j = 0; j < 8; ++j) {
            q1[j] = 1e-3 * phi[j];
            d1[j] = 1e-9 * phi[j];
        }
        start_reaching(c, dt, q1, d1, q0, v0);
        plan.propagator().first_step(q0, v0, q1, d1);  // the plan's own q^1, d^1
        double u1 = 0.0, u_before = 0.0, u_free = 0.0;
        for (std::size_t j = 0; j < n; ++j) {
            const double d2 = d1[j] - plan.propagator().beta()[j] * q1[j];
            u1 += phi[j] * q1[j];
            u_before += phi[j] * d1[j];
            u_free += phi[j] * d2;
        }
        ASSERT_GT(u_before, 0.0);
        ASSERT_LT(u_free, -u_before);  // the free step ends below u^0 = u^1 - u^-
        // The obstacle between the free prediction and the point at n = 1.
        if (on_grid)
            c.obstacle_height_m[120] = u1 + 0.5 * u_free;
        else
            c.point_obstacles[0].height_m = u1 + 0.5 * u_free;
        const Plan placed(c, dt);
        NewtonImpact string(placed, q0, v0);
        string.step();
        const double h = string.energy();
        string.step();
        ASSERT_TRUE(string.touched_obstacle()) << "e = " << e;
        std::cout << (on_grid ? "grid" : "exact") << " point moving away, e = " << e << ": loss "
                  << string.impact_loss() / h << " of H, u^2 - u^0 = " << string.displacement(phi) - (u1 - u_before)
                  << " m (u^- = " << u_before << " m)\n";
        EXPECT_NEAR(string.impact_loss(), 0.0, 1e-12 * h) << "e = " << e;
        EXPECT_NEAR(string.displacement(phi), u1 - u_before, 1e-9 * std::abs(u_before)) << "e = " << e;
        EXPECT_NEAR(string.energy() + string.dissipated(), h, 1e-13 * h);
    }
}

TEST(NewtonImpact, OneImpactOnAGridPointLosesOneMinusESquaredOfTheNormalKineticEnergy) {
    expect_one_impact_closed_form(true);
}

TEST(NewtonImpact, OneImpactOnAnExactPointLosesOneMinusESquaredOfTheNormalKineticEnergy) {
    expect_one_impact_closed_form(false);
}

TEST(NewtonImpact, APointMovingAwayFromAGridObstacleTakesAnImpulseThatDoesNoWork) {
    expect_a_point_moving_away_takes_no_energy(true);
}

TEST(NewtonImpact, APointMovingAwayFromAnExactObstacleTakesAnImpulseThatDoesNoWork) {
    expect_a_point_moving_away_takes_no_energy(false);
}

TEST(NewtonImpact, ScreeningSkipsPointsWithoutChangingTheResult) {
    const Case c = impact_bass(400000.0, 0.05, 2e-3, 0.0);
    PlanOptions plain;
    plain.screen_contacts = false;
    const Plan fast_plan(c, 1.0 / c.run.sample_rate_hz), plain_plan(c, 1.0 / c.run.sample_rate_hz, plain);
    NewtonImpact fast(fast_plan, c.initial_displacement, c.initial_velocity);
    NewtonImpact straight(plain_plan, c.initial_displacement, c.initial_velocity);
    for (int n = 0; n < 20000; ++n) {
        fast.step();
        straight.step();
    }
    double diff = 0.0, norm = 0.0;
    for (std::size_t j = 0; j < c.mode_count(); ++j) {
        diff += std::pow(fast.modal_displacement()[j] - straight.modal_displacement()[j], 2);
        norm += std::pow(straight.modal_displacement()[j], 2);
    }
    std::cout << "points looked at: " << fast.points_checked() << " screened, " << straight.points_checked()
              << " all; contact steps " << fast.contact_steps() << "\n";
    EXPECT_GT(fast.contact_steps(), 20);
    EXPECT_EQ(fast.contact_steps(), straight.contact_steps());
    EXPECT_LT(std::sqrt(diff / norm), 1e-12);
    EXPECT_LT(fast.points_checked() * 10, straight.points_checked());
}

// The observation at 0.8 m over the run, by the penalty (law = penalty, K) or the impact law.
std::vector<double> observation(Case c, long steps) {
    const Plan plan(c, 1.0 / c.run.sample_rate_hz);
    const std::vector<double> shape = plan.basis().mode_shapes_at(0.8);
    std::vector<double> u;
    if (c.contact.law == ContactLawKind::impact) {
        NewtonImpact string(plan, c.initial_displacement, c.initial_velocity);
        for (long n = 0; n < steps; ++n, string.step()) u.push_back(string.displacement(shape));
    } else {
        Stepper string(plan, c.initial_displacement, c.initial_velocity);
        for (long n = 0; n < steps; ++n, string.step()) u.push_back(string.displacement(shape));
    }
    return u;
}

TEST(NewtonImpact, APenaltyOnAPointTendsToTheImpactLawAsItsStiffnessGrows) {
    // One grid point under the plucked string, half way down from where the pluck starts it. The
    // energy-conserving penalty loses nothing at any K, so its rigid limit is e = 1, not e = 0.
    Case c = testing::small_bass(400000.0, 0.03, 1e-3);
    const std::size_t point = 100;
    const std::vector<double> phi = ModalBasis(c.string.length_m, c.mode_count()).mode_shapes_at(c.grid_point(point));
    double u0 = 0.0;
    for (std::size_t j = 0; j < c.mode_count(); ++j) u0 += phi[j] * c.initial_displacement[j];
    ASSERT_GT(u0, 0.0);
    std::fill(c.obstacle_height_m.begin(), c.obstacle_height_m.end(), -std::numeric_limits<double>::infinity());
    c.point_obstacles.clear();
    c.obstacle_height_m[point] = -0.5 * u0;
    const long steps = 12000;
    c.contact.law = ContactLawKind::impact;
    c.contact.restitution = 1.0;
    const std::vector<double> elastic = observation(c, steps);
    c.contact.restitution = 0.0;
    const std::vector<double> plastic = observation(c, steps);
    // The restitution acts on the mass of the string's contact point (mu dx at a grid point):
    // the two impact laws differ little, and the penalty's limit lies between them.
    const double between = testing::relative_l2(plastic, elastic);
    std::cout << "impact e = 0 against e = 1: relative L2 " << between << "\n";
    c.contact.law = ContactLawKind::penalty;
    double previous = std::numeric_limits<double>::infinity(), step_before = previous;
    std::vector<double> u_before;
    for (double k : {1e9, 1e11, 1e13, 1e15, 1e17}) {
        c.contact.stiffness = k;
        const std::vector<double> u = observation(c, steps);
        const double to_elastic = testing::relative_l2(u, elastic), to_plastic = testing::relative_l2(u, plastic);
        const double step = u_before.empty() ? previous : testing::relative_l2(u, u_before);
        std::cout << "K = " << k << ": relative L2 to e = 1: " << to_elastic << ", to e = 0: " << to_plastic
                  << ", to the K 100 x lower: " << step << "\n";
        EXPECT_LT(to_elastic, previous) << "K = " << k;
        if (!u_before.empty()) {
            EXPECT_LT(step, step_before) << "K = " << k;  // the penalty's own sequence converges
        }
        previous = to_elastic;
        step_before = step;
        u_before = u;
    }
    EXPECT_LT(previous, between);
}

// The small bass nearly at rest, pressed onto its frets by a force gesture at 0.5 m (5 N over
// 5 ms, held to 20 ms, let go), with the impact law.
Case pressed_bass(double restitution) {
    std::string text = builtin_case_text("bass-pluck");
    text.replace(text.find("modes = 862"), 11, "modes = 255");
    text.replace(text.find("amplitude = 0.5e-3"), 18, "amplitude = 1e-6");
    text += "\n[[gesture]]\ntype = \"force\"\nposition = 0.5\n"
            "force = [[0.0, 0.0], [0.005, 5.0], [0.02, 5.0], [0.021, 0.0]]\n";
    Case c = parse_case(text, "pressed-bass.toml", DataSource::builtin());
    c.run.sample_rate_hz = 400000.0;
    c.run.duration_s = 0.04;
    c.contact.law = ContactLawKind::impact;
    c.contact.restitution = restitution;
    c.validate();  // a force gesture beside the impact law is a case it steps
    return c;
}

TEST(NewtonImpact, AForceGesturePressesTheStringOntoTheFretsWithTheBalanceKept) {
    for (double e : {0.0, 1.0}) {
        const Case c = pressed_bass(e);
        PlanOptions plain;
        plain.screen_contacts = false;
        const Plan plan(c, 1.0 / c.run.sample_rate_hz), plain_plan(c, 1.0 / c.run.sample_rate_hz, plain);
        NewtonImpact string(plan, c.initial_displacement, c.initial_velocity);
        NewtonImpact straight(plain_plan, c.initial_displacement, c.initial_velocity);
        string.step();
        straight.step();
        const double h0 = string.energy();
        double worst = 0.0, most_work = 0.0;
        std::vector<double> errors;
        const long steps = std::lround(c.run.duration_s * c.run.sample_rate_hz);
        for (long n = 1; n < steps; ++n) {
            string.step();
            straight.step();
            most_work = std::max(most_work, std::abs(string.work()));
            errors.push_back(string.energy() - string.work() + string.dissipated() - h0);
        }
        for (double err : errors) worst = std::max(worst, std::abs(err) / std::max(h0, most_work));
        double diff = 0.0, norm = 0.0;
        for (std::size_t j = 0; j < c.mode_count(); ++j) {
            diff += std::pow(string.modal_displacement()[j] - straight.modal_displacement()[j], 2);
            norm += std::pow(straight.modal_displacement()[j], 2);
        }
        std::cout << "e = " << e << ": work " << most_work << " J (H^1/2 " << h0 << " J), contact steps "
                  << string.contact_steps() << ", impact loss " << string.impact_loss() << " J, balance " << worst
                  << ", screened against all points " << std::sqrt(diff / norm) << "\n";
        EXPECT_GT(most_work, 1e3 * h0) << e;  // the gesture's work is what the string holds
        EXPECT_GT(string.contact_steps(), 100) << e;
        EXPECT_LT(worst, 1e-12) << e;
        EXPECT_EQ(string.contact_steps(), straight.contact_steps()) << e;
        EXPECT_LT(std::sqrt(diff / norm), 1e-10) << e;
        if (e == 0.0) {
            EXPECT_GT(string.impact_loss(), 1e-3 * most_work);
        } else {
            EXPECT_LT(std::abs(string.impact_loss()), 1e-12 * most_work);
        }
    }
}

TEST(NewtonImpact, TheImpactLawRefusesWhatItCannotStep) {
    Case c = impact_bass(400000.0, 0.01, 0.0, 0.0);
    c.add_fret_finger(5, "fret");
    try {
        c.validate();
        FAIL() << "a finger with the impact law was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("fret"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("impact"), std::string::npos) << e.what();
    }
    Case bad = impact_bass(400000.0, 0.01, 0.0, 1.5);
    try {
        bad.validate();
        FAIL() << "restitution 1.5 was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("contact.restitution"), std::string::npos) << e.what();
    }
}

// The sound a run hands out at 48 kHz.
class Sound : public RunObserver {
public:
    AudioRequest audio_request() const override { return {48000.0}; }
    void audio(long, std::span<const double> s) override { samples.insert(samples.end(), s.begin(), s.end()); }
    std::vector<double> samples;
};

TEST(NewtonImpact, AFreeFlightRunIsTheSteppedRunToRoundOff) {
    // Between contacts the run jumps whole output intervals in closed form, its sound written in
    // closed form too (AudioBand): the outputs of the run that steps everything.
    const Case c = impact_bass(400000.0, 0.1, 2e-3, 0.0);
    RecordedRun runs[2];
    std::vector<double> sounds[2];
    for (int flying = 0; flying < 2; ++flying) {
        ResultRecorder recorder;
        Sound sound;
        RunObserver* observers[] = {&recorder, &sound};
        RunOptions options;
        options.free_flight = flying == 1;
        simulate(c, observers, options);
        runs[flying] = recorder.take();
        sounds[flying] = sound.samples;
    }
    const RunSummary& flown = runs[1].summary;
    std::cout << "free flight " << flown.free_flight_fraction << " of the steps; observation "
              << testing::relative_l2(runs[1].observation, runs[0].observation) << ", sound "
              << testing::relative_l2(sounds[1], sounds[0]) << " apart\n";
    EXPECT_GT(flown.free_flight_fraction, 0.3);
    EXPECT_EQ(runs[0].summary.free_flight_fraction, 0.0);
    EXPECT_EQ(flown.contact_steps, runs[0].summary.contact_steps);
    EXPECT_GT(flown.contact_steps, 20);
    EXPECT_LT(testing::relative_l2(runs[1].observation, runs[0].observation), 1e-11);
    EXPECT_LT(testing::relative_l2(sounds[1], sounds[0]), 1e-4);  // the resampler's stop band
    EXPECT_LT(flown.max_relative_balance_error, 1e-12);
}

TEST(NewtonImpact, ItsSnapshotsAreTheStringsShapeAndAFlightNeverJumpsOne) {
    // The shape at each snapshot is the modal state on the grid (the first: the initial shape),
    // and a free flight stops short of a snapshot, so the flying run's are the stepped run's.
    const Case c = impact_bass(400000.0, 0.05, 2e-3, 0.0);
    RecordedRun runs[2];
    for (int flying = 0; flying < 2; ++flying) {
        ResultRecorder recorder(10000.0);
        RunObserver* observers[] = {&recorder};
        RunOptions options;
        options.free_flight = flying == 1;
        simulate(c, observers, options);
        runs[flying] = recorder.take();
    }
    const RecordedRun& flown = runs[1];
    const std::size_t n = c.mode_count();
    ASSERT_EQ(flown.snapshot_time.size(), 501u);  // t = 0, then every 0.1 ms up to 50 ms
    ASSERT_EQ(flown.snapshots.size(), 501u * n);
    EXPECT_GT(flown.summary.free_flight_fraction, 0.1);
    EXPECT_GT(flown.summary.contact_steps, 20);
    EXPECT_LT(testing::relative_l2(flown.snapshots, runs[0].snapshots), 1e-11);
    const Plan plan(c, 1.0 / c.run.sample_rate_hz);
    std::vector<double> initial(n);
    plan.basis().to_grid(c.initial_displacement, initial);
    double scale = 0.0, first = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        scale = std::max(scale, std::abs(initial[i]));
        first = std::max(first, std::abs(flown.snapshots[i] - initial[i]));
    }
    EXPECT_GT(scale, 1e-3);
    EXPECT_LT(first, 1e-14 * scale);
    for (std::size_t k = 0; k < flown.snapshot_time.size(); ++k)
        EXPECT_NEAR(flown.snapshot_time[k], 1e-4 * static_cast<double>(k), 1e-12);
}

TEST(NewtonImpact, TheProgramRunsTheImpactLawAndRefusesBadLawsNamingTheKey) {
    testing::ScratchDir dir("impact");
    const auto run = testing::run_cli("run bass-rigid-frets --duration 0.002 -q --out " + dir.str() + "/rigid");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    std::ifstream in(dir.path() / "rigid" / "summary.json");
    const std::string summary((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(summary.find("\"contact_law\": \"impact\""), std::string::npos) << summary;
    struct Bad {
        std::string arguments, key;
    };
    const std::string case_text = builtin_case_text("bass-rigid-frets");
    const auto write_case = [&](const std::string& name, const std::string& from, const std::string& to) {
        std::string text = case_text;
        text.replace(text.find(from), from.size(), to);
        const std::filesystem::path path = dir.path() / name;
        std::ofstream(path) << text;
        return path.string();
    };
    for (const Bad& bad : std::vector<Bad>{
             {"bass-pop --law rigid", "--law"},
             {"bass-pop --law impact --restitution 1.5", "--restitution"},
             {"bass-pop --law impact --restitution -0.1", "--restitution"},
             {"bass-pop --restitution 0.5", "--restitution"},
             {"bass-pop --law impact --fret 5", "--fret"},
             {"bass-pop --law impact --polarisations 2", "string.polarisations"},
             {write_case("law.toml", "law = \"impact\"", "law = \"rigid\"") + "", "contact.law"},
             {write_case("e.toml", "restitution = 0", "restitution = 1.2"), "contact.restitution"},
         }) {
        const auto r = testing::run_cli("run " + bad.arguments + " -q --duration 0.001 --out " + dir.str() + "/bad");
        EXPECT_EQ(r.exit_code, 2) << bad.arguments << ": " << r.output;
        EXPECT_NE(r.output.find(bad.key), std::string::npos) << bad.arguments << ": " << r.output;
    }
}

TEST(NewtonImpact, ASweepNamesTheLawAndStepsItsRestitution) {
    testing::ScratchDir dir("impact-sweep");
    std::ofstream(dir.path() / "sweep.toml") << "[sweep]\ncase = \"bass-pop\"\n[set]\n\"run.duration\" = 0.005\n"
                                                "\"run.fs\" = 1000000\n\"contact.law\" = \"impact\"\n"
                                                "[[parameter]]\nkey = \"contact.restitution\"\nvalues = [0.0, 1.0]\n";
    const auto r = testing::run_cli("sweep " + (dir.path() / "sweep.toml").string() + " --out " + dir.str() + "/out");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    std::ifstream in(dir.path() / "out" / "results.csv");
    std::string header, line;
    std::getline(in, header);
    int ok = 0;
    while (std::getline(in, line)) ok += line.find(",ok,") != std::string::npos ? 1 : 0;
    EXPECT_EQ(ok, 2) << r.output;
}

}  // namespace
}  // namespace fretbuzz
