#include "fretbuzz/scheme/SineTransform.hpp"

#include <fftw3.h>

#include <algorithm>
#include <mutex>
#include <stdexcept>

namespace fretbuzz {

std::mutex& fftw_planner_mutex() {
    static std::mutex mutex;
    return mutex;
}

SineTransform::SineTransform(std::size_t n, bool measure) : n_(n) {
    std::lock_guard lock(fftw_planner_mutex());
    buffer_ = fftw_alloc_real(n);
    if (buffer_ == nullptr) throw std::bad_alloc();
    std::fill(buffer_, buffer_ + n, 0.0);
    const unsigned flags = measure ? FFTW_MEASURE : FFTW_ESTIMATE;
    plan_ = fftw_plan_r2r_1d(static_cast<int>(n), buffer_, buffer_, FFTW_RODFT00, flags);
    if (plan_ == nullptr) {
        fftw_free(buffer_);
        throw std::runtime_error("FFTW could not plan a sine transform of length " + std::to_string(n));
    }
}

SineTransform::~SineTransform() {
    std::lock_guard lock(fftw_planner_mutex());
    fftw_destroy_plan(static_cast<fftw_plan>(plan_));
    fftw_free(buffer_);
}

double SineTransform::planned_flops() const {
    std::lock_guard lock(fftw_planner_mutex());
    return fftw_estimate_cost(static_cast<fftw_plan>(plan_));
}

void SineTransform::apply(std::span<const double> input, std::span<double> output, double scale) const {
    std::copy(input.begin(), input.end(), buffer_);
    fftw_execute(static_cast<fftw_plan>(plan_));
    std::transform(buffer_, buffer_ + n_, output.begin(), [scale](double y) { return scale * y; });
}

}  // namespace fretbuzz
