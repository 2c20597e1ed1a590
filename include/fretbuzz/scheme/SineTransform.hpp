#pragma once
// The type-I discrete sine transform that maps modal coordinates to the string
// shape on the grid and back (u = S q, q = dx S^T u). Like FFTW itself, the
// costly planning happens once in the constructor; apply() is the cheap part.
#include <cstddef>
#include <mutex>
#include <span>

namespace fretbuzz {

// FFTW's planner is not thread-safe (execution of distinct plans is): every plan made or
// destroyed anywhere in fretbuzz holds this lock.
std::mutex& fftw_planner_mutex();

class SineTransform {
public:
    // Plans an unnormalised RODFT00 of length n: y_k = 2 sum_j x_j sin(pi (j+1)(k+1)/(n+1)).
    // measure = true lets FFTW time candidate algorithms (slower to plan, faster to run).
    explicit SineTransform(std::size_t n, bool measure = false);
    ~SineTransform();
    SineTransform(const SineTransform&) = delete;
    SineTransform& operator=(const SineTransform&) = delete;

    std::size_t size() const { return n_; }
    // FFTW's own estimate of the plan's floating-point operations (deterministic for a
    // given FFTW and length): what a cost model compares against row products.
    double planned_flops() const;
    // output[k] = scale * RODFT00(input)[k]; input and output may be the same span.
    void apply(std::span<const double> input, std::span<double> output, double scale) const;

private:
    std::size_t n_;
    double* buffer_;
    void* plan_;
};

}  // namespace fretbuzz
