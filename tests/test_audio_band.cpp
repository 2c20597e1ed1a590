// The audio written in closed form during long flights equals the per-step signal through the
// resampler, and the resampler's measured gain predicts its output for damped sinusoids.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <span>
#include <stdexcept>
#include <vector>

#include "TestSupport.hpp"
#include "fretbuzz/output/AudioWriter.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/run/Resampler.hpp"
#include "fretbuzz/run/ResultRecorder.hpp"
#include "fretbuzz/run/Simulation.hpp"

namespace fretbuzz {
namespace {

using testing::relative_l2;

struct Audio {
    std::vector<std::vector<double>> u, v;
    RecordedRun recorded;  // the output-rate rows (CSV and HDF5 signals)
    RunSummary summary;
};

Audio audio_of(const Case& c, bool closed_form, bool free_flight = true, bool audio_thread = true) {
    std::vector<std::filesystem::path> paths(c.observation_points_m.size(), "/dev/null");
    AudioWriter u(paths, c.run.audio_rate_hz), v(paths, c.run.audio_rate_hz, AudioSignal::velocity);
    ResultRecorder recorder;
    RunObserver* observers[] = {&u, &v, &recorder};
    RunOptions options;
    options.closed_form_audio = closed_form;
    options.free_flight = free_flight;
    options.per_step_thread = audio_thread;
    Audio a;
    a.summary = simulate(c, observers, options);
    a.recorded = recorder.take();
    for (std::size_t p = 0; p < paths.size(); ++p) {
        a.u.push_back(u.samples(p));
        a.v.push_back(v.samples(p));
    }
    return a;
}

TEST(AudioBand, ResamplerGainPredictsItsOutputForDampedSinusoids) {
    const double fs = 4e6, rate = 48000.0;
    Resampler r(fs, rate, 1);
    ASSERT_EQ(r.input_period(), 250);
    ASSERT_EQ(r.output_period(), 3);
    EXPECT_NEAR(std::abs(r.gain(0.0)), 1.0, 1e-8);
    for (double f : {41.0, 3000.0, 15000.0, 21000.0, 22500.0}) {
        const std::complex<double> s(-40.0, 2.0 * std::numbers::pi * f), c(0.3, -0.8);
        std::vector<double> x(250 * 2000), y;
        for (std::size_t n = 0; n < x.size(); ++n) x[n] = std::real(c * std::exp(s * (static_cast<double>(n) / fs)));
        r.clear();
        r.process(x, y, true);
        ASSERT_GE(y.size(), 6000u);
        std::vector<double> expected, got;
        const std::complex<double> g = r.gain(s);
        for (long k = 1000; k < 5000; ++k) {
            expected.push_back(std::real(g * c * std::exp(s * (static_cast<double>(k) / rate))));
            got.push_back(y[static_cast<std::size_t>(k)]);
        }
        EXPECT_LT(relative_l2(got, expected), 1e-8) << f << " Hz";
    }
}

// The filter's response is measured once per pair of rates in a process: a second resampler
// (a later run's) describes the same filter, bit for bit, and the gain still predicts what a
// resampler at other rates (its own measurement) outputs.
TEST(AudioBand, ResamplersAtTheSameRatesShareOneMeasurement) {
    const Resampler first(4e6, 48000.0, 1), second(4e6, 48000.0, 2);
    const std::complex<double> s(-40.0, 2.0 * std::numbers::pi * 15000.0);
    EXPECT_EQ(second.reach(), first.reach());
    EXPECT_EQ(second.gain(s), first.gain(s));
    Resampler other(44100.0 * 8, 44100.0, 1);
    EXPECT_NEAR(std::abs(other.gain(0.0)), 1.0, 1e-8);
    const std::complex<double> c(0.3, -0.8), z(-40.0, 2.0 * std::numbers::pi * 3000.0);
    std::vector<double> x(8 * 4000), y;
    for (std::size_t n = 0; n < x.size(); ++n) x[n] = std::real(c * std::exp(z * (static_cast<double>(n) / (44100.0 * 8))));
    other.process(x, y, true);
    ASSERT_GE(y.size(), 3000u);
    std::vector<double> expected, got;
    for (long k = 1000; k < 3000; ++k) {
        expected.push_back(std::real(other.gain(z) * c * std::exp(z * (static_cast<double>(k) / 44100.0))));
        got.push_back(y[static_cast<std::size_t>(k)]);
    }
    EXPECT_LT(relative_l2(got, expected), 1e-8);
}

// The closed form against the per-step flights it replaces (both resampled by the same filter),
// and both against every mode stepped every step: the closed form adds nothing to the error
// the flights already make (modes above 0.6 x the audio rate left out near contacts).
void expect_same_audio(const Case& c, double displacement_tolerance, double velocity_tolerance) {
    const Audio fast = audio_of(c, true), reference = audio_of(c, false), stepped = audio_of(c, false, false);
    ASSERT_GT(fast.summary.free_flight_fraction, 0.5);
    std::printf("last contact %.4f s, free flight %.3f\n", fast.summary.last_contact_s, fast.summary.free_flight_fraction);
    // The string itself moves as it did (flights with fewer modes checked one by one may stop
    // at other steps, and with no row to take and no point able to touch a flight is one jump
    // of every mode: the same free motion, round-off apart, which later contacts amplify a little).
    EXPECT_NEAR(fast.summary.energy_final_j, reference.summary.energy_final_j, 1e-10 * reference.summary.energy_initial_j);
    EXPECT_EQ(fast.summary.contact_steps, reference.summary.contact_steps);
    // The output-rate rows are the same samples of the same motion: only round-off apart.
    ASSERT_EQ(fast.recorded.time, reference.recorded.time);
    EXPECT_LT(relative_l2(fast.recorded.observation, reference.recorded.observation), 1e-10);
    EXPECT_LT(relative_l2(fast.recorded.energy, reference.recorded.energy), 1e-10);
    EXPECT_LT(relative_l2(fast.recorded.dissipated, reference.recorded.dissipated), 1e-10);
    EXPECT_LT(relative_l2(fast.recorded.peak_contact_force, reference.recorded.peak_contact_force), 1e-9);
    for (std::size_t p = 0; p < fast.u.size(); ++p) {
        ASSERT_EQ(fast.u[p].size(), reference.u[p].size());
        ASSERT_EQ(fast.v[p].size(), reference.v[p].size());
        const double eu = relative_l2(fast.u[p], reference.u[p]), ev = relative_l2(fast.v[p], reference.v[p]);
        const double fu = relative_l2(fast.u[p], stepped.u[p]), fv = relative_l2(fast.v[p], stepped.v[p]);
        const double ru = relative_l2(reference.u[p], stepped.u[p]), rv = relative_l2(reference.v[p], stepped.v[p]);
        std::printf("%s point %zu: closed form vs per-step flights %.3g (displacement), %.3g (velocity); "
                    "against every step: closed form %.3g / %.3g, per-step flights %.3g / %.3g\n",
                    c.name.c_str(), p, eu, ev, fu, fv, ru, rv);
        EXPECT_LT(eu, displacement_tolerance);
        EXPECT_LT(ev, velocity_tolerance);
        EXPECT_LT(fu, 1.01 * ru + displacement_tolerance);
        EXPECT_LT(fv, 1.01 * rv + velocity_tolerance);
    }
}

TEST(AudioBand, ClosedFormAudioEqualsTheResampledPerStepSignalOnTheBassPop) {
    Case c = load_case("bass-pop");
    c.run.duration_s = 0.3;
    c.observation_points_m.push_back(0.3);
    expect_same_audio(c, 1e-7, 5e-6);
}

TEST(AudioBand, ClosedFormAudioEqualsTheResampledPerStepSignalOnAPointObstacle) {
    // Lowered so that the string touches it during its first periods only; then it flies.
    Case c = load_case("guitar-point");
    c.run.duration_s = 0.3;
    for (double& h : c.obstacle_height_m)
        if (std::isfinite(h)) h -= 1.2e-3;
    expect_same_audio(c, 1e-7, 5e-6);
}

// The tanpura at 48 kHz with the modes below fs/2.
Case tanpura_at_48khz(double seconds) { return testing::builtin_at_rate("tanpura", 48000.0, seconds); }

// The audio files fed on a thread of their own while the string steps: the same calls in the
// same order, so the same samples bit for bit, with the closed form (band entered and left
// around contacts) and with a per-step signal only (an audio-rate run, no flight).
TEST(AudioBand, AudioOnItsOwnThreadIsTheAudioMadeInline) {
    Case pop = load_case("bass-pop");
    pop.run.duration_s = 0.25;
    pop.observation_points_m.push_back(0.3);
    const Case tanpura = tanpura_at_48khz(0.2);
    for (const Case* c : {static_cast<const Case*>(&pop), &tanpura}) {
        const Audio threaded = audio_of(*c, true, true, true), inline_ = audio_of(*c, true, true, false);
        if (c == &pop) {
            ASSERT_GT(threaded.summary.free_flight_fraction, 0.5);
        }
        ASSERT_EQ(threaded.u.size(), inline_.u.size());
        for (std::size_t p = 0; p < threaded.u.size(); ++p) {
            ASSERT_GT(threaded.u[p].size(), 1000u) << c->name;
            EXPECT_EQ(threaded.u[p], inline_.u[p]) << c->name << " point " << p;
            EXPECT_EQ(threaded.v[p], inline_.v[p]) << c->name << " point " << p;
        }
    }
}

// Out of the band (a run too short for it to enter), the frames of each flight are made on the
// audio's thread from the flight's start, stepping the audio modes as the flight does: the
// samples are those of the frames the run forms itself without the band, bit for bit.
TEST(AudioBand, FlightFramesMadeBesideTheRunAreTheRunsOwn) {
    Case pop = load_case("bass-pop");
    pop.run.duration_s = 0.005;
    pop.observation_points_m.push_back(0.3);
    const Audio band = audio_of(pop, true), run = audio_of(pop, false);
    ASSERT_GT(band.summary.free_flight_fraction, 0.5);
    ASSERT_EQ(band.u.size(), run.u.size());
    for (std::size_t p = 0; p < band.u.size(); ++p) {
        ASSERT_GT(band.u[p].size(), 200u);
        EXPECT_EQ(band.u[p], run.u[p]) << "point " << p;
        EXPECT_EQ(band.v[p], run.v[p]) << "point " << p;
    }
}

// What an observer that asks for audio receives: finished samples at its rate, in order, from
// sample 0 to the run's end, while the run goes on (not all at its end), the same samples an
// audio file gets; audio along y asked of a run with one polarisation is refused.
class AudioLog : public RunObserver {
public:
    AudioRequest audio_request() const override { return {.rate_hz = 48000.0}; }
    void observation(double, std::span<const double>) override { ++rows; }
    void audio(long first_sample, std::span<const double> samples) override {
        if (calls++ == 0) rows_at_first_audio = rows;
        contiguous = contiguous && first_sample == static_cast<long>(received.size() / 2);
        received.insert(received.end(), samples.begin(), samples.end());
    }
    long rows = 0, rows_at_first_audio = -1, calls = 0;
    bool contiguous = true;
    std::vector<double> received;  // two points, interleaved
};

TEST(AudioBand, ObserversReceiveFinishedSamplesInOrderWhileTheRunGoesOn) {
    Case c = load_case("bass-pop");
    c.run.duration_s = 0.3;
    c.observation_points_m.push_back(0.3);
    AudioLog log;
    AudioWriter writer({"/dev/null", "/dev/null"}, 48000.0);
    RunObserver* observers[] = {&log, &writer};
    RunOptions options;
    options.per_step_thread = false;  // (the calls' order against the rows is then the run's own)
    const RunSummary s = simulate(c, observers, options);
    ASSERT_GT(s.free_flight_fraction, 0.5);  // the closed form wrote most of it
    EXPECT_TRUE(log.contiguous);
    EXPECT_GT(log.calls, 10);
    EXPECT_GT(log.rows_at_first_audio, 0);
    EXPECT_LT(log.rows_at_first_audio, log.rows / 2);
    // Up to the run's end: round(duration x rate) samples, or one more where the last falls on it.
    ASSERT_EQ(log.received.size(), 2 * writer.samples(0).size());
    EXPECT_NEAR(static_cast<double>(writer.samples(0).size()), 0.3 * 48000.0, 1.0);
    for (std::size_t k = 0; k < log.received.size() / 2; ++k) {
        ASSERT_EQ(log.received[2 * k], writer.samples(0)[k]) << k;
        ASSERT_EQ(log.received[2 * k + 1], writer.samples(1)[k]) << k;
    }
    struct AlongY : AudioLog {
        AudioRequest audio_request() const override { return {.rate_hz = 48000.0, .angle_deg = 90.0}; }
    } y;
    RunObserver* along_y[] = {&y};
    EXPECT_THROW(simulate(c, along_y), std::invalid_argument);
}

// An audio file that fails while the run goes on: the failure reaches the caller (and the run
// stops), as a failed write of the results file does.
class FailingAudio : public RunObserver {
public:
    AudioRequest audio_request() const override { return {.rate_hz = 48000.0}; }
    void audio(long, std::span<const double> samples) override {
        samples_ += static_cast<long>(samples.size());
        if (samples_ >= 20000) throw std::runtime_error("audio: the disk is full");
    }

private:
    long samples_ = 0;
};

TEST(AudioBand, AFailureOnTheAudioThreadReachesTheCaller) {
    const Case c = tanpura_at_48khz(2.0);
    FailingAudio audio;
    RunObserver* observers[] = {&audio};
    try {
        simulate(c, observers);
        FAIL() << "the run went on";
    } catch (const std::runtime_error& e) {
        EXPECT_STREQ(e.what(), "audio: the disk is full");
    }
}

}  // namespace
}  // namespace fretbuzz
