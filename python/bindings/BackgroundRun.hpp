#pragma once
// Long library calls (a sweep, a set-up map) from Python: the work runs on a thread of its
// own, with the interpreter's lock released, while the calling thread hands each report the
// work posts to a Python callback (so callbacks run on the caller's thread, one at a time),
// looks for Ctrl-C every 0.2 s and asks whether to stop. Anything the callback raises, and
// Ctrl-C, sets the stop flag (the work stops after what is under way), waits for the thread
// and propagates; an exception of the work itself is rethrown once it has ended.
//
// Called on a thread other than the main one, the call may meet the interpreter's end (Ctrl-C
// on the main thread, the program exiting while a daemon thread maps): taking the lock back
// then ends this thread by unwinding it (pthread_exit). That unwinding must not start inside
// a destructor (gil_scoped_release's would std::terminate) nor leave the work's thread
// running on this stack: the lock is taken back by plain calls, and the unwinding stops the
// work and waits for it before going on.
#include <pybind11/pybind11.h>

#ifdef __GLIBCXX__
#include <cxxabi.h>
#endif

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

namespace fretbuzz::python {

// f() (C++ only, no Python) with the interpreter's lock released, taken back by a plain call
// (see above: at the interpreter's end this thread unwinds from there, not from a destructor).
template <class F>
auto without_gil(F&& f) {
    std::optional<decltype(f())> result;
    std::exception_ptr failure;
    PyThreadState* unlocked = PyEval_SaveThread();
    try {
        result.emplace(f());
    } catch (...) {
        failure = std::current_exception();
    }
    PyEval_RestoreThread(unlocked);
    if (failure) std::rethrow_exception(failure);
    return std::move(*result);
}

template <class Report>
class BackgroundRun {
public:
    // Called by the work (any thread).
    void post(Report report) {
        std::lock_guard lock(mutex_);
        reports_.push_back(std::move(report));
        wake_.notify_one();
    }
    // What the work asks to know whether to stop.
    bool stopping() const { return stop_.load(); }

    // Runs work() to its end; deliver(report) for each report, should_stop() between waits.
    void run(const std::function<void()>& work, const std::function<void(const Report&)>& deliver,
             const std::function<bool()>& should_stop = {}) {
        namespace py = pybind11;
        std::exception_ptr failure;
        bool finished = false;
        std::thread runner([&] {
            try {
                work();
            } catch (...) {
                failure = std::current_exception();
            }
            std::lock_guard lock(mutex_);
            finished = true;
            wake_.notify_one();
        });
        try {
            while (true) {
                std::deque<Report> batch;
                bool done = false;
                PyThreadState* unlocked = PyEval_SaveThread();
                {
                    std::unique_lock lock(mutex_);
                    wake_.wait_for(lock, std::chrono::milliseconds(200), [&] { return finished || !reports_.empty(); });
                    batch.swap(reports_);
                    done = finished;
                }
                PyEval_RestoreThread(unlocked);  // at the interpreter's end, unwinds this thread from here
                for (const Report& r : batch) deliver(r);
                if (done) break;
                if (PyErr_CheckSignals() != 0) throw py::error_already_set();
                if (should_stop && should_stop()) stop_ = true;
            }
#ifdef __GLIBCXX__
        } catch (abi::__forced_unwind&) {  // the thread is ending, without the interpreter's lock
            stop_ = true;
            runner.join();
            throw;
#endif
        } catch (...) {
            stop_ = true;
            PyThreadState* unlocked = PyEval_SaveThread();
            runner.join();
            PyEval_RestoreThread(unlocked);
            throw;
        }
        runner.join();
        if (failure) std::rethrow_exception(failure);
    }

private:
    std::mutex mutex_;
    std::condition_variable wake_;
    std::deque<Report> reports_;
    std::atomic<bool> stop_{false};
};

}  // namespace fretbuzz::python
