#include "AudioStreams.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "fretbuzz/run/Resampler.hpp"

namespace fretbuzz {

namespace {
// Frames handed to the resampler at once.
constexpr std::size_t kBlockFrames = 1 << 14;

long floor_div(long a, long b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

bool same_kind(const AudioRequest& a, const AudioRequest& b) {
    return a.rate_hz == b.rate_hz && a.signal == b.signal && a.angle_deg == b.angle_deg;
}
}  // namespace

class AudioStreams::Stream {
public:
    Stream(const AudioRequest& request, double fs, std::size_t points)
        : request_(request), resampler_(fs, request.rate_hz, points), width_(points) {
        const double a = request.angle_deg * std::numbers::pi / 180.0;
        // Exactly y alone at 90 degrees (cos would leave 6e-17 of z).
        const bool right = std::fmod(request.angle_deg, 90.0) == 0.0;
        along_z_ = right ? std::round(std::cos(a)) : std::cos(a);
        along_y_ = right ? std::round(std::sin(a)) : std::sin(a);
        input_.reserve(kBlockFrames * width_);
        block_.reserve(kBlockFrames * width_);
    }

    const AudioRequest& request() const { return request_; }
    const Resampler& resampler() const { return resampler_; }
    void add(RunObserver* o) { observers_.push_back(o); }

    void frame(std::span<const double> u, std::span<const double> velocity, std::span<const double> y) {
        if (request_.angle_deg != 0.0) {
            for (std::size_t p = 0; p < width_; ++p)
                input_.push_back(along_z_ * u[p] + along_y_ * (p < y.size() ? y[p] : 0.0));
        } else {
            // One or two numbers: pushed one by one (a range insert calls memmove per step).
            for (const double v : request_.signal == AudioSignal::velocity ? velocity : u) input_.push_back(v);
        }
        ++frame_step_;
        if (input_.size() >= kBlockFrames * width_) drain(false);
    }

    void frames(const double* u, const double* velocity, std::size_t count) {
        if (request_.angle_deg != 0.0) throw std::logic_error("AudioStreams: frames without y for audio along y");
        const double* from = request_.signal == AudioSignal::velocity ? velocity : u;
        // Drained at the same frames as frame() would: the resampler sees the same blocks.
        for (std::size_t done = 0; done < count;) {
            const std::size_t n = std::min(kBlockFrames - input_.size() / width_, count - done);
            input_.insert(input_.end(), from + done * width_, from + (done + n) * width_);
            frame_step_ += static_cast<long>(n);
            done += n;
            if (input_.size() >= kBlockFrames * width_) drain(false);
        }
    }

    void begin_segment(long step, long first_sample) {
        settle(first_sample);
        resampler_.clear();
        segment_sample_ = step / resampler_.input_period() * resampler_.output_period();
        keep_from_ = first_sample;
        frame_step_ = step;
    }

    void end_segment(long last_sample) {
        drain(true);
        cut(last_sample + 1);
        settle(last_sample + 1);
    }

    void band_samples(long first_sample, std::span<const double> u, std::span<const double> velocity) {
        const std::span<const double> frames = request_.signal == AudioSignal::velocity ? velocity : u;
        for (std::size_t f = 0; f < frames.size() / width_; ++f)
            place(first_sample + static_cast<long>(f), frames.data() + f * width_);
    }

    void finish(double duration_s) {
        drain(true);
        cut(std::llround(duration_s * request_.rate_hz) + 1);
        settle(std::numeric_limits<long>::max());
    }

    void settle(long before) {
        before = std::min(before, placed_end());
        if (before <= base_) return;
        const auto values = static_cast<std::size_t>(before - base_) * width_;
        const std::span<const double> settled(pending_.data(), values);
        for (RunObserver* o : observers_) o->audio(base_, settled);
        pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(values));
        base_ = before;
    }

    long hold_back = -1;  // -1: nothing is ever overwritten

private:
    long placed_end() const { return base_ + static_cast<long>(pending_.size() / width_); }

    void drain(bool flush) {
        block_.clear();
        resampler_.process(input_, block_, flush);
        input_.clear();
        for (std::size_t f = 0; f < block_.size() / width_; ++f, ++segment_sample_)
            if (segment_sample_ >= keep_from_) place(segment_sample_, block_.data() + f * width_);
        // The segment's outputs so far are final up to `hold_back` before its last frame's
        // instant: the closed form, if it takes over, starts after them. (Past its outputs lie
        // the closed form's samples that it is about to overwrite.)
        if (hold_back < 0) {
            settle(segment_sample_);
        } else {
            const long last = floor_div((frame_step_ - 1) * resampler_.output_period(), resampler_.input_period());
            settle(std::min(segment_sample_, last - hold_back + 1));
        }
    }

    void place(long sample, const double* frame) {
        if (sample < base_) throw std::logic_error("AudioStreams: a sample written after it was handed out");
        const auto at = static_cast<std::size_t>(sample - base_) * width_;
        if (at >= pending_.size()) pending_.resize(at + width_, 0.0);  // later sources overwrite earlier ones
        std::copy_n(frame, width_, pending_.begin() + static_cast<std::ptrdiff_t>(at));
    }

    void cut(long end) {
        if (placed_end() > end) pending_.resize(static_cast<std::size_t>(std::max(0L, end - base_)) * width_);
    }

    AudioRequest request_;
    double along_z_ = 1.0, along_y_ = 0.0;
    std::vector<RunObserver*> observers_;
    Resampler resampler_;
    std::size_t width_;
    std::vector<double> input_;  // interleaved, one frame per time step
    std::vector<double> block_;  // interleaved resampler output
    long segment_sample_ = 0;    // sample index of the current segment's next output frame
    long keep_from_ = 0;         // the segment's outputs before this sample are dropped
    long frame_step_ = 0;        // the step of the next per-step frame
    std::vector<double> pending_;  // samples from base_ on, not yet handed out
    long base_ = 0;
};

AudioStreams::AudioStreams(std::span<RunObserver* const> observers, double fs, std::size_t points, int polarisations) {
    for (RunObserver* o : observers) {
        const AudioRequest r = o->audio_request();
        if (r.rate_hz == 0.0) continue;
        if (!(r.rate_hz > 0.0 && std::isfinite(r.rate_hz)))
            throw std::invalid_argument("audio: a rate of " + std::to_string(r.rate_hz) + " Hz");
        if (r.angle_deg != 0.0 && (polarisations != 2 || r.signal != AudioSignal::displacement))
            throw std::invalid_argument(
                "audio along a direction other than z: only the displacement, with two polarisations");
        const auto same = std::find_if(streams_.begin(), streams_.end(),
                                       [&](const auto& s) { return same_kind(s->request(), r); });
        Stream& s =
            same != streams_.end() ? **same : *streams_.emplace_back(std::make_unique<Stream>(r, fs, points));
        s.add(o);
        velocity_ = velocity_ || r.signal == AudioSignal::velocity;
    }
}

AudioStreams::~AudioStreams() = default;

double AudioStreams::lowest_rate_hz() const {
    double rate = std::numeric_limits<double>::infinity();
    for (const auto& s : streams_) rate = std::min(rate, s->request().rate_hz);
    return rate;
}

const Resampler* AudioStreams::common_resampler() const {
    if (streams_.empty()) return nullptr;
    for (const auto& s : streams_)
        if (s->request().rate_hz != streams_.front()->request().rate_hz || s->request().angle_deg != 0.0) return nullptr;
    return &streams_.front()->resampler();
}

void AudioStreams::hold_back(long reach) {
    for (const auto& s : streams_) s->hold_back = reach;
}

void AudioStreams::frame(std::span<const double> u, std::span<const double> velocity, std::span<const double> y) {
    for (const auto& s : streams_) s->frame(u, velocity, y);
}

void AudioStreams::frames(const double* u, const double* velocity, std::size_t count) {
    for (const auto& s : streams_) s->frames(u, velocity, count);
}

void AudioStreams::begin_segment(long step, long first_sample) {
    for (const auto& s : streams_) s->begin_segment(step, first_sample);
}

void AudioStreams::end_segment(long last_sample) {
    for (const auto& s : streams_) s->end_segment(last_sample);
}

void AudioStreams::band_samples(long first_sample, std::span<const double> u, std::span<const double> velocity) {
    for (const auto& s : streams_) s->band_samples(first_sample, u, velocity);
}

void AudioStreams::settled_before(long sample) {
    for (const auto& s : streams_) s->settle(sample);
}

void AudioStreams::finish(double duration_s) {
    for (const auto& s : streams_) s->finish(duration_s);
}

}  // namespace fretbuzz
