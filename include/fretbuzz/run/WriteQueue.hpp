#pragma once
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace fretbuzz {

// A thread that runs an output file's writes in order while the run steps on. results.h5
// posts its chunk writes here (extending datasets, converting, shuffling and deflating them):
// at audio rates the contact map's compression alone was a tenth of the run's thread. HDF5
// (Debian's serial build) is not thread-safe, so the queue's thread must be the only one
// calling HDF5 between the first post() and drain(). The first failure is kept, the jobs
// after it are dropped, and the next post() or drain() rethrows it: a run never commits a
// file whose writes failed.
class WriteQueue {
public:
    WriteQueue();
    ~WriteQueue();  // drops what is still queued (the run failed), waits for the running job
    WriteQueue(const WriteQueue&) = delete;
    WriteQueue& operator=(const WriteQueue&) = delete;

    void post(std::function<void()> job);  // waits while the queue is long (bounded memory)
    void drain();                          // waits until every job has run; rethrows a failure

private:
    void work();

    std::deque<std::function<void()>> jobs_;
    bool busy_ = false, stopping_ = false;
    std::exception_ptr failure_;
    std::mutex mutex_;
    std::condition_variable changed_;
    std::thread thread_;
};

}  // namespace fretbuzz
