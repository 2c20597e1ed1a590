#include "fretbuzz/numerics/SineTransform.hpp"

#include <fftw3.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <mutex>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "Multiversion.hpp"

namespace fretbuzz {

std::mutex& fftw_planner_mutex() {
    static std::mutex mutex;
    return mutex;
}

std::size_t SineTransform::extended_length(std::size_t n) { return 2 * (n + 1); }

namespace {
// One plan per length and kind for the whole process: every SineTransform of that length
// executes it on its own buffer (FFTW's new-array execution; fftw_alloc_real aligns them all
// alike). Plans live until the process ends: the registry is never destroyed, so that a
// transform used during exit still finds its plan and the plans stay reachable (not leaks).
std::map<std::pair<std::size_t, bool>, fftw_plan>& plans() {
    static auto* registry = new std::map<std::pair<std::size_t, bool>, fftw_plan>;
    return *registry;
}

// FFTW's wisdom (what measuring planners learnt) is read once per process from the cache
// file and written back after each new measured plan; a cache that cannot be read or written
// only costs the measuring again.
void import_wisdom_once() {
    static bool done = false;
    if (done) return;
    done = true;
    const std::filesystem::path path = fftw_wisdom_path();
    if (!path.empty()) fftw_import_wisdom_from_filename(path.c_str());
}

void export_wisdom() {
    const std::filesystem::path path = fftw_wisdom_path();
    if (path.empty()) return;
    std::error_code error;
    std::filesystem::create_directories(path.parent_path(), error);
    // Written aside and renamed: a process reading it meanwhile never sees half a file.
    const std::filesystem::path partial = path.string() + ".partial";
    if (fftw_export_wisdom_to_filename(partial.c_str()) != 0) std::filesystem::rename(partial, path, error);
    if (error) std::filesystem::remove(partial, error);
}
}  // namespace

std::filesystem::path fftw_wisdom_path() {
    if (const char* dir = std::getenv("XDG_CACHE_HOME"); dir != nullptr && *dir != '\0')
        return std::filesystem::path(dir) / "fretbuzz" / "fftw-wisdom";
    if (const char* home = std::getenv("HOME"); home != nullptr && *home != '\0')
        return std::filesystem::path(home) / ".cache" / "fretbuzz" / "fftw-wisdom";
    return {};
}

std::size_t fftw_plans_made() {
    std::lock_guard lock(fftw_planner_mutex());
    return plans().size();
}

SineTransform::SineTransform(std::size_t n, bool measure) : n_(n) {
    std::lock_guard lock(fftw_planner_mutex());
    const std::size_t m = extended_length(n);
    input_ = fftw_alloc_real(m);
    spectrum_ = fftw_alloc_complex(m / 2 + 1);
    if (input_ == nullptr || spectrum_ == nullptr) {
        release();
        throw std::bad_alloc();
    }
    fftw_plan& plan = plans()[{n, measure}];
    if (plan == nullptr) {
        import_wisdom_once();
        // Measuring overwrites the arrays it plans on: scratch ones, not this transform's.
        double* scratch = fftw_alloc_real(m);
        fftw_complex* scratch_spectrum = fftw_alloc_complex(m / 2 + 1);
        if (scratch != nullptr && scratch_spectrum != nullptr)
            plan = fftw_plan_dft_r2c_1d(static_cast<int>(m), scratch, scratch_spectrum,
                                        measure ? FFTW_MEASURE : FFTW_ESTIMATE);
        fftw_free(scratch);
        fftw_free(scratch_spectrum);
        if (plan == nullptr) {
            plans().erase({n, measure});
            release();
            throw std::runtime_error("FFTW could not plan a sine transform of length " + std::to_string(n));
        }
        if (measure) export_wisdom();
    }
    plan_ = plan;
}

void SineTransform::release() {
    fftw_free(input_);
    fftw_free(spectrum_);
}

SineTransform::~SineTransform() {
    std::lock_guard lock(fftw_planner_mutex());
    release();
}

double SineTransform::planned_flops() const {
    std::lock_guard lock(fftw_planner_mutex());
    return fftw_estimate_cost(static_cast<fftw_plan>(plan_));
}

namespace {
// The copies around the DFT, compiled for AVX2 too where the processor has it (the baseline
// build moved two numbers at a time: a tenth of a flat obstacle's contact step). Moves and one
// product each: the same bits either way.

// 0, x_0 .. x_{n-1}, 0, -x_{n-1} .. -x_0 into out (2(n + 1) numbers).
FRETBUZZ_MULTIVERSION void odd_extension(const double* __restrict x, double* __restrict out, std::size_t n) {
    const std::size_t m = 2 * (n + 1);
    out[0] = out[n + 1] = 0.0;  // written every call: nothing relies on FFTW preserving its input
    for (std::size_t j = 0; j < n; ++j) out[j + 1] = x[j];
    for (std::size_t j = 0; j < n; ++j) out[m - 1 - j] = -x[j];
}

// out[k] = c Im X_{k+1}: the imaginary parts of a spectrum stored as (re, im) pairs.
FRETBUZZ_MULTIVERSION void scaled_imaginary(const double* __restrict spectrum, double c, double* __restrict out,
                                           std::size_t n) {
    for (std::size_t k = 0; k < n; ++k) out[k] = c * spectrum[2 * (k + 1) + 1];
}
}  // namespace

void SineTransform::apply(std::span<const double> input, std::span<double> output, double scale) const {
    // The odd extension 0, x_0 .. x_{n-1}, 0, -x_{n-1} .. -x_0 of length m = 2(n + 1) has the
    // spectrum X_k = -2i sum_j x_j sin(pi (j + 1) k / (n + 1)): the transform is -Im X_{k+1}.
    odd_extension(input.data(), input_, n_);
    auto* spectrum = static_cast<fftw_complex*>(spectrum_);
    fftw_execute_dft_r2c(static_cast<fftw_plan>(plan_), input_, spectrum);
    scaled_imaginary(&spectrum[0][0], -scale, output.data(), n_);
}

}  // namespace fretbuzz
