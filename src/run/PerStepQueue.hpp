#pragma once
// The run's audio (resampling, the closed-form audio band, the observers' audio() calls) made
// on a thread of its own, so that a run's second core works on the audio while the first
// steps the string. Calls reach the audio streams in the order the run makes them: per-step
// frames are gathered into batches, and any other job (a segment's start or end, closed-form
// samples) is posted after the frames before it. A failure on that thread (an observer's) is
// rethrown by the next post() or by drain(), as the results file's writes are (see WriteQueue).
#include <cstddef>
#include <functional>
#include <span>
#include <vector>

#include "fretbuzz/run/WriteQueue.hpp"

namespace fretbuzz {

class PerStepQueue {
public:
    // Where the frames go, on the queue's thread: `count` frames of `points` values each, and
    // their velocities (nullptr unless wanted), interleaved (AudioStreams::frames).
    using Sink = std::function<void(const double* u, const double* velocity, std::size_t count)>;
    PerStepQueue(Sink sink, std::size_t points, bool velocity);

    void frame(std::span<const double> u, std::span<const double> velocity);  // batched
    void post(std::function<void()> job);  // after the frames before it
    // A job that makes `frames` per-step calls of its own (a flight's free motion), run in its
    // place among the batch's frames: in order, without a job and a wake-up of its own.
    void defer(std::function<void()> job, std::size_t frames);
    void drain();  // every call made; rethrows a failure

private:
    void flush();
    void flush_if_full();

    struct Deferred {
        std::size_t at;  // frames of the batch before it
        std::function<void()> job;
    };
    Sink sink_;
    std::size_t points_;
    bool velocity_;
    std::vector<double> u_, v_;  // the batch's frames, interleaved
    std::vector<Deferred> deferred_;
    std::size_t deferred_frames_ = 0;
    WriteQueue queue_;
};

}  // namespace fretbuzz
