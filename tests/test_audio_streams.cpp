// The run's audio streams with the closed-form band, driven as the run drives them, on a string
// that never touches anything: however the sources take turns (segments of per-step frames,
// the closed form, segments started again), the samples handed out are the whole per-step
// signal through one resampler, each handed out once and never rewritten, at every ratio of
// the simulation rate to the audio rate (equal, non-integer, integer, large).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "../src/run/AudioBand.hpp"
#include "../src/run/AudioStreams.hpp"
#include "../src/run/PerStepQueue.hpp"
#include "TestSupport.hpp"
#include "fretbuzz/run/Resampler.hpp"
#include "fretbuzz/numerics/Kernels.hpp"
#include "fretbuzz/scheme/ModalPropagator.hpp"

namespace fretbuzz {
namespace {

using testing::relative_l2;

// An observer that keeps what it is handed, checking that it comes in order, without gaps.
class AudioTake : public RunObserver {
public:
    AudioTake(double rate_hz, AudioSignal signal) : request_{.rate_hz = rate_hz, .signal = signal} {}
    AudioRequest audio_request() const override { return request_; }
    void audio(long first_sample, std::span<const double> samples) override {
        in_order = in_order && first_sample * 2 == static_cast<long>(received.size());
        received.insert(received.end(), samples.begin(), samples.end());
    }
    std::vector<double> point(std::size_t p) const {
        std::vector<double> x;
        for (std::size_t k = p; k < received.size(); k += 2) x.push_back(received[k]);
        return x;
    }
    bool in_order = true;
    std::vector<double> received;  // two points, interleaved

private:
    AudioRequest request_;
};

// What happens after a contact: flights until the band is entered (or `flights` of them where
// `enter` is false), `after` more complete flights, and a last flight of `tail` steps cut short
// (0: none; contact may come at the next step).
struct Episode {
    bool enter;
    long flights, after, tail;
};

// A few damped modes, all below the output band's edge, of a string read at two points.
class FreeString {
public:
    FreeString(double fs, double rate, long stride, bool thread)
        : fs_(fs), stride_(stride), propagator_(modes(), 1.0 / fs) {
        const std::size_t h = propagator_.size();
        for (const double x : {0.1, 0.37}) {
            shapes_.emplace_back(h);
            for (std::size_t j = 0; j < h; ++j) shapes_.back()[j] = std::sin(static_cast<double>(j + 1) * std::numbers::pi * x);
        }
        for (std::size_t j = 0; j < h; ++j) q_.push_back(1e-3 / static_cast<double>(j + 1));
        d_.assign(h, 0.0);
        displacement_.emplace(rate, AudioSignal::displacement);
        velocity_.emplace(rate, AudioSignal::velocity);
        RunObserver* observers[] = {&*displacement_, &*velocity_};
        streams_.emplace(observers, fs, 2, 1);
        if (thread)
            queue_.emplace([this](const double* u, const double* v, std::size_t count) { streams_->frames(u, v, count); },
                           2, true);
        if (!AudioBand::applies(*streams_, propagator_, h, stride)) throw std::logic_error("no closed form here");
        band_.emplace(*streams_, propagator_, h, shapes_, stride, queue_ ? &*queue_ : nullptr);
    }

    // The run's calls for one episode (RunLoop::run, fly, report_flight), then a contact of a
    // few steps and steps up to the next output step, where flights may start again.
    void play(const Episode& e) {
        const long first = flights_;
        while (e.enter ? !band_->in_band() : flights_ - first < e.flights) fly(stride_);
        for (long k = 0; k < e.after; ++k) fly(stride_);
        if (e.tail > 0) fly(e.tail);
        for (long k = 0; k < 3 || n_ % stride_ != 0; ++k) step();
    }

    // The run's end: the last segment, every stream cut at the run's duration.
    void finish() {
        band_->resume(n_, q_, d_);
        if (queue_) queue_->drain();
        streams_->finish(static_cast<double>(n_) / fs_);
    }

    long steps() const { return n_; }
    long flights() const { return flights_; }
    const AudioTake& displacement() const { return *displacement_; }
    const AudioTake& velocity() const { return *velocity_; }
    // Every step's frame (as the run forms them), interleaved: the reference's input.
    const std::vector<double>& u() const { return u_; }
    const std::vector<double>& v() const { return v_; }

    void start() {
        record();
        deliver();
        for (long k = 0; k < 3 || n_ % stride_ != 0; ++k) step();
    }

private:
    static ModeTable modes() {
        ModeTable t;
        t.frequency_hz = {82.4, 165.3, 249.1, 333.7, 1200.5, 5100.2, 9800.9, 15000.3};
        t.sigma_per_s = {0.5, 0.8, 1.1, 1.5, 4.0, 12.0, 25.0, 40.0};
        t.source.assign(t.frequency_hz.size(), ModeSource::model);
        return t;
    }

    void advance() {
        kernels::advance(propagator_.decay().data(), propagator_.beta().data(), nullptr, nullptr, q_.data(), d_.data(),
                         q_.size());
        ++n_;
        record();
    }
    void record() {
        for (const auto& shape : shapes_) {
            u_.push_back(kernels::dot(shape.data(), q_.data(), q_.size()));
            v_.push_back(kernels::dot(shape.data(), d_.data(), d_.size()) * fs_);
        }
    }
    void deliver() {
        const std::span<const double> u(u_.end() - 2, u_.end()), v(v_.end() - 2, v_.end());
        if (queue_)
            queue_->frame(u, v);
        else
            streams_->frame(u, v);
    }
    void step() {  // a step of the scheme (contact may act): a per-step frame
        band_->resume(n_, q_, d_);
        advance();
        band_->stepped(n_);
        deliver();
    }
    void fly(long steps) {  // the band makes the flight's frames, or the closed form covers it
        const bool in_band = band_->in_band(), complete = steps == stride_;
        if (!in_band) band_->flight_start(q_, d_);
        for (long k = 0; k < steps; ++k) advance();
        ++flights_;
        if (in_band) {
            if (complete)
                band_->flown(n_, true, q_, d_);
            else
                band_->resume(n_, q_, d_);
        } else {
            band_->flight_frames(steps);
            band_->flown(n_, complete, q_, d_);
        }
    }

    double fs_;
    long stride_;
    ModalPropagator propagator_;
    std::vector<std::vector<double>> shapes_;
    std::vector<double> q_, d_, u_, v_;
    std::optional<AudioTake> displacement_, velocity_;
    std::optional<AudioStreams> streams_;
    std::optional<PerStepQueue> queue_;
    std::optional<AudioBand> band_;
    long n_ = 0, flights_ = 0;
};

// The signal a single resampler makes of every frame, cut as the streams cut it.
std::vector<double> resampled(const std::vector<double>& frames, double fs, double rate, long steps, std::size_t p) {
    Resampler r(fs, rate, 2);
    std::vector<double> out, x;
    r.process(frames, out, true);
    const auto count = static_cast<std::size_t>(std::llround(static_cast<double>(steps) / fs * rate) + 1);
    for (std::size_t k = p; k < std::min(out.size(), 2 * count); k += 2) x.push_back(out[k]);
    return x;
}

void expect_the_resampled_signal(double fs, double rate, long stride, bool thread) {
    const std::string what = std::to_string(fs) + " Hz to " + std::to_string(rate) + " Hz" + (thread ? ", threaded" : "");
    FreeString s(fs, rate, stride, thread);
    s.start();
    // Flights of a samples' batch and more (several closed-form jobs), then left at once, ...
    const long long_stay = static_cast<long>(std::ceil(2.5 * 4096.0 * fs / rate / static_cast<double>(stride)));
    const Episode episodes[] = {
        {true, 0, 0, 0},              // contact at the very step the band was entered
        {true, 0, 0, 1},              // a step after it
        {true, 0, 0, stride / 2},     // a flight cut short right after entering
        {true, 0, 1, stride - 1},     // one output interval in the band, then most of another
        {false, 2, 0, 5},             // contact before the band is entered
        {true, 0, 3, 0},              // a few intervals in the band
        {true, 0, long_stay, stride / 3},
        {true, 0, 2, 0},
    };
    for (const Episode& e : episodes) ASSERT_NO_THROW(s.play(e)) << what << " at step " << s.steps();
    ASSERT_NO_THROW(s.finish()) << what;
    EXPECT_TRUE(s.displacement().in_order) << what;
    EXPECT_TRUE(s.velocity().in_order) << what;
    for (std::size_t p = 0; p < 2; ++p) {
        for (const bool velocity : {false, true}) {
            const std::vector<double> got = (velocity ? s.velocity() : s.displacement()).point(p);
            const std::vector<double> expected = resampled(velocity ? s.v() : s.u(), fs, rate, s.steps(), p);
            ASSERT_EQ(got.size(), expected.size()) << what;
            double peak = 0.0, worst = 0.0;
            std::size_t at = 0;
            for (std::size_t k = 0; k < got.size(); ++k) {
                peak = std::max(peak, std::abs(expected[k]));
                if (std::abs(got[k] - expected[k]) > worst) {
                    worst = std::abs(got[k] - expected[k]);
                    at = k;
                }
            }
            std::printf("%s, point %zu, %s: %zu samples, relative L2 %.3g, worst %.3g of the peak (sample %zu)\n",
                        what.c_str(), p, velocity ? "velocity" : "displacement", got.size(),
                        relative_l2(got, expected), worst / peak, at);
            EXPECT_LT(relative_l2(got, expected), 1e-8) << what;
            EXPECT_LT(worst, 1e-7 * peak) << what << ", sample " << at;
        }
    }
}

TEST(AudioStreams, SamplesAreHandedOutOnceAtTheAudioRateItself) {
    for (const bool thread : {false, true}) expect_the_resampled_signal(48000.0, 48000.0, 48, thread);
}

TEST(AudioStreams, SamplesAreHandedOutOnceAtANonIntegerRatio) {
    for (const bool thread : {false, true}) expect_the_resampled_signal(44100.0, 48000.0, 44, thread);
}

TEST(AudioStreams, SamplesAreHandedOutOnceAtTwiceTheAudioRate) {
    for (const bool thread : {false, true}) expect_the_resampled_signal(96000.0, 48000.0, 96, thread);
}

TEST(AudioStreams, SamplesAreHandedOutOnceAtFourMegahertz) {
    for (const bool thread : {false, true}) expect_the_resampled_signal(4e6, 48000.0, 83, thread);
}

}  // namespace
}  // namespace fretbuzz
