#pragma once
// The run's audio. Each kind of audio the observers ask for (RunObserver::audio_request: a
// rate, displacement or velocity, a direction) is one stream: the signal at every time step,
// band-limited and resampled to its rate by a Resampler of the stream's own (libsoxr,
// streaming), or, over long stretches where no contact can act, written at its rate in closed
// form by the AudioBand. The sources take turns: a segment of resampled per-step frames, the
// closed form, a segment again...; where they overlap the later one counts (a segment's
// outputs before `first_sample` are dropped, its outputs after `last_sample` too). A stream
// hands its samples to the observers that asked for them in order, once no later source can
// overwrite them, and at the run's end the rest, cut at the run's duration.
#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#include "fretbuzz/run/RunObserver.hpp"

namespace fretbuzz {

class Resampler;

class AudioStreams {
public:
    // The streams the observers ask for, from a run at fs with `points` observation points and
    // `polarisations` (audio along y needs 2; std::invalid_argument otherwise).
    AudioStreams(std::span<RunObserver* const> observers, double fs, std::size_t points, int polarisations);
    ~AudioStreams();
    AudioStreams(const AudioStreams&) = delete;
    AudioStreams& operator=(const AudioStreams&) = delete;

    bool empty() const { return streams_.empty(); }
    bool wants_velocity() const { return velocity_; }
    double lowest_rate_hz() const;
    // The resampler that describes every stream's filter, if the closed form can write them
    // all: one output rate, along z; nullptr otherwise.
    const Resampler* common_resampler() const;
    // With a closed form: its outputs from `reach` output samples before the last frame's
    // instant on may still be overwritten, and are held back until they cannot be.
    void hold_back(long reach);

    // A per-step frame: u and (if wanted) the velocity at the points, y with two polarisations.
    void frame(std::span<const double> u, std::span<const double> velocity, std::span<const double> y = {});
    // `count` frames of one polarisation, interleaved (velocity: nullptr unless wanted).
    void frames(const double* u, const double* velocity, std::size_t count);
    // A segment's frames start at `step` (a multiple of the resampler's input period).
    void begin_segment(long step, long first_sample);
    void end_segment(long last_sample);
    // Closed-form samples from first_sample on (interleaved frames of every point).
    void band_samples(long first_sample, std::span<const double> u, std::span<const double> velocity);
    // No source will write before this sample: the samples before it are handed out.
    void settled_before(long sample);
    // The end of the run (at t = duration_s): the last segment's filter tail, each stream cut
    // to its samples up to t, all of them handed out.
    void finish(double duration_s);

private:
    class Stream;
    std::vector<std::unique_ptr<Stream>> streams_;
    bool velocity_ = false;
};

}  // namespace fretbuzz
