// What a sweep adds to its spec: the buzz reference of each run, and the check of every
// run's case before any runs.
#include "fretbuzz/sweep/Sweep.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <limits>
#include <mutex>
#include <thread>
#include <vector>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/analysis/BuzzMetrics.hpp"

namespace fretbuzz {

Case obstacle_free_case(const SweepSpec& spec, const SweepRun& run) {
    // A fretted note keeps what stops it (the finger, the fret it presses on): its reference
    // is the same note with nothing to buzz against past the stopping fret.
    Case c = sweep_case(spec, run);
    if (c.fingers.empty()) return sweep_case_without_obstacle(spec, run);
    return without_obstacle_from(c, first_buzz_point(c));
}

void check_sweep(const SweepSpec& spec, const SweepCheckProgress& progress, unsigned jobs) {
    const std::size_t total = spec.runs.size();
    const unsigned threads = static_cast<unsigned>(std::min<std::size_t>(
        std::max<std::size_t>(total, 1), jobs != 0 ? jobs : std::max(1u, std::thread::hardware_concurrency())));
    std::atomic<std::size_t> next{0};
    std::mutex mutex;  // guards the fields below and the progress callback
    std::size_t checked = 0;
    std::size_t first_bad = total;  // the lowest failing run: the one reported, whatever the threads' order
    std::exception_ptr failure;
    auto worker = [&] {
        for (std::size_t k = next++; k < total; k = next++) {
            {
                std::lock_guard lock(mutex);
                if (k > first_bad) return;
            }
            try {
                throw_if_stopped();
                const SweepRun run = spec.runs[k];
                const Case c = sweep_case(spec, run);
                try {
                    c.validate();
                } catch (const InputError& e) {
                    throw InputError(spec.source_name + ", " + describe(run) + ": " + e.what());
                }
                std::lock_guard lock(mutex);
                ++checked;
                if (progress && first_bad == total) progress(checked, total);
            } catch (...) {
                std::lock_guard lock(mutex);
                if (k < first_bad) {
                    first_bad = k;
                    failure = std::current_exception();
                }
            }
        }
    };
    {
        std::vector<std::jthread> workers;
        for (unsigned t = 1; t < threads; ++t) workers.emplace_back(worker);
        worker();  // this thread too: a sweep of one run starts none
    }
    if (failure) std::rethrow_exception(failure);
}

}  // namespace fretbuzz
