#include "fretbuzz/run/WriteQueue.hpp"
#include "fretbuzz/SubnormalFlush.hpp"

#include <utility>

namespace fretbuzz {

namespace {
// Jobs queued before post() waits for the thread: bounded memory if the disk is slow.
constexpr std::size_t kMaxQueuedJobs = 64;
}  // namespace

WriteQueue::WriteQueue() : thread_([this] { work(); }) {}

WriteQueue::~WriteQueue() {
    {
        const std::lock_guard lock(mutex_);
        stopping_ = true;
        jobs_.clear();
    }
    changed_.notify_all();
    thread_.join();
}

void WriteQueue::post(std::function<void()> job) {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [this] { return jobs_.size() < kMaxQueuedJobs || failure_; });
    if (failure_) std::rethrow_exception(failure_);
    jobs_.push_back(std::move(job));
    lock.unlock();
    changed_.notify_all();
}

void WriteQueue::drain() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [this] { return (jobs_.empty() && !busy_) || failure_; });
    if (failure_) std::rethrow_exception(failure_);
}

void WriteQueue::work() {
    const SubnormalFlush flushed;  // the jobs filter decaying signals
    std::unique_lock lock(mutex_);
    while (true) {
        changed_.wait(lock, [this] { return !jobs_.empty() || stopping_; });
        if (stopping_) return;
        std::function<void()> job = std::move(jobs_.front());
        jobs_.pop_front();
        busy_ = true;
        lock.unlock();
        std::exception_ptr failure;
        try {
            job();
        } catch (...) {
            failure = std::current_exception();
        }
        job = nullptr;  // its rows are freed here, not under the lock
        lock.lock();
        busy_ = false;
        if (failure && !failure_) {
            failure_ = failure;
            jobs_.clear();
        }
        changed_.notify_all();
    }
}

}  // namespace fretbuzz
