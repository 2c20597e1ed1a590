#pragma once
// The type-I discrete sine transform that maps modal coordinates to the string
// shape on the grid and back (u = S q, q = dx S^T u). FFTW plans once per process for
// each length (later transforms of that length share the plan); apply() is the cheap part.
// It runs as the real DFT of the odd extension (length 2(n + 1)) into buffers kept with
// the transform: FFTW's own RODFT00 allocates that extension at every call and uses no
// SIMD for it (slower, the same accuracy: docs/performance.md).
// Measured plans (measure = true) keep FFTW's wisdom in a cache file across processes.
#include <cstddef>
#include <filesystem>
#include <mutex>
#include <span>

namespace fretbuzz {

// FFTW's planner is not thread-safe (execution of distinct plans is): every plan made or
// destroyed anywhere in fretbuzz holds this lock.
std::mutex& fftw_planner_mutex();

// Where FFTW's wisdom is kept: $XDG_CACHE_HOME/fretbuzz/fftw-wisdom, else
// ~/.cache/fretbuzz/fftw-wisdom (empty: no cache). Read at the first plan of a process.
std::filesystem::path fftw_wisdom_path();
// Distinct sine-transform plans made so far in this process.
std::size_t fftw_plans_made();

class SineTransform {
public:
    // Plans an unnormalised type-I sine transform of length n (what FFTW calls RODFT00),
    // y_k = 2 sum_j x_j sin(pi (j+1)(k+1)/(n+1)), run as FFTW's real DFT of 2(n + 1) points.
    // measure = true lets FFTW time candidate algorithms (slower to plan, faster to run; the
    // wisdom cache makes that a one-off per machine).
    explicit SineTransform(std::size_t n, bool measure = false);
    ~SineTransform();
    SineTransform(const SineTransform&) = delete;
    SineTransform& operator=(const SineTransform&) = delete;

    std::size_t size() const { return n_; }
    // FFTW's own cost estimate of the plan (fftw_estimate_cost: deterministic for a given
    // FFTW and length): what a cost model compares against row products.
    double planned_flops() const;
    // output[k] = scale * RODFT00(input)[k]; input and output may be the same span.
    void apply(std::span<const double> input, std::span<double> output, double scale) const;

    // Length of the real DFT it runs: 2(n + 1).
    static std::size_t extended_length(std::size_t n);

private:
    void release();

    std::size_t n_;
    double* input_ = nullptr;    // the odd extension, 2(n + 1) reals
    void* spectrum_ = nullptr;   // its n + 2 complex coefficients (fftw_complex)
    void* plan_ = nullptr;
};

}  // namespace fretbuzz
