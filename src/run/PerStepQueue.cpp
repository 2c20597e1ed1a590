#include "PerStepQueue.hpp"

#include <utility>

namespace fretbuzz {

namespace {
// Frames per batch: few jobs (each a lock and a wake-up), little memory (a few hundred kB).
constexpr std::size_t kBatchFrames = 8192;
}  // namespace

PerStepQueue::PerStepQueue(Sink sink, std::size_t points, bool velocity)
    : sink_(std::move(sink)), points_(points), velocity_(velocity) {
    u_.reserve(kBatchFrames * points_);
    if (velocity_) v_.reserve(kBatchFrames * points_);
}

void PerStepQueue::frame(std::span<const double> u, std::span<const double> velocity) {
    u_.insert(u_.end(), u.begin(), u.end());
    if (velocity_) v_.insert(v_.end(), velocity.begin(), velocity.end());
    flush_if_full();
}

void PerStepQueue::defer(std::function<void()> job, std::size_t frames) {
    deferred_.push_back({u_.size() / points_, std::move(job)});
    deferred_frames_ += frames;
    flush_if_full();
}

void PerStepQueue::flush_if_full() {
    // A batch counts its frames and those its deferred jobs will make (in values: no division
    // at every step).
    if (u_.size() + deferred_frames_ * points_ >= kBatchFrames * points_) flush();
}

void PerStepQueue::flush() {
    if (u_.empty() && deferred_.empty()) return;
    queue_.post([&sink = sink_, points = points_, u = std::move(u_), v = std::move(v_),
                 deferred = std::move(deferred_)] {
        const auto deliver = [&](std::size_t from, std::size_t to) {
            if (to > from) sink(u.data() + from * points, v.empty() ? nullptr : v.data() + from * points, to - from);
        };
        std::size_t k = 0;
        for (const Deferred& d : deferred) {
            deliver(k, d.at);
            d.job();
            k = d.at;
        }
        deliver(k, u.size() / points);
    });
    u_ = {};
    v_ = {};
    deferred_ = {};
    deferred_frames_ = 0;
    u_.reserve(kBatchFrames * points_);
    if (velocity_) v_.reserve(kBatchFrames * points_);
}

void PerStepQueue::post(std::function<void()> job) {
    flush();
    queue_.post(std::move(job));
}

void PerStepQueue::drain() {
    flush();
    queue_.drain();
}

}  // namespace fretbuzz
