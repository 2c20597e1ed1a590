#pragma once
// The per-step observers (the audio files: resampling, the closed-form audio band) fed on a
// thread of their own, so that a run's second core works on the audio while the first steps
// the string. Calls reach the observers in the order the run makes them: per-step frames are
// gathered into batches, and any other job (a segment's start or end, closed-form samples) is
// posted after the frames before it. A failure on that thread is rethrown by the next post()
// or by drain(), as the results file's writes are (see WriteQueue).
#include <cstddef>
#include <functional>
#include <span>
#include <vector>

#include "fretbuzz/run/WriteQueue.hpp"
#include "fretbuzz/run/RunObserver.hpp"

namespace fretbuzz {

class PerStepQueue {
public:
    // Whether these observers accept their per-step calls from another thread: each says it
    // receives nothing else between begin() and finish().
    static bool applies(std::span<RunObserver* const> per_step);
    PerStepQueue(std::span<RunObserver* const> per_step, std::size_t points, bool velocity);

    void frame(std::span<const double> u, std::span<const double> velocity);  // every_step, batched
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
    std::span<RunObserver* const> observers_;
    std::size_t points_;
    bool velocity_;
    std::vector<double> u_, v_;  // the batch's frames, interleaved
    std::vector<Deferred> deferred_;
    std::size_t deferred_frames_ = 0;
    WriteQueue queue_;
};

}  // namespace fretbuzz
