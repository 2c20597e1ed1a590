#pragma once
// The wall and CPU time of a search (the advice, the fret dress), reported with its answer.
#include <chrono>
#include <ctime>

namespace fretbuzz {

class SearchClock {
public:
    double wall_seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }
    // The process's CPU time: the search's notes play on worker threads.
    double cpu_seconds() const { return static_cast<double>(std::clock() - cpu_) / CLOCKS_PER_SEC; }

private:
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
    std::clock_t cpu_ = std::clock();
};

}  // namespace fretbuzz
