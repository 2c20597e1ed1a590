#include "fretbuzz/scheme/SineTransform.hpp"

#include <fftw3.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <mutex>
#include <stdexcept>
#include <system_error>
#include <utility>

namespace fretbuzz {

std::mutex& fftw_planner_mutex() {
    static std::mutex mutex;
    return mutex;
}

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
    buffer_ = fftw_alloc_real(n);
    if (buffer_ == nullptr) throw std::bad_alloc();
    fftw_plan& plan = plans()[{n, measure}];
    if (plan == nullptr) {
        import_wisdom_once();
        // Measuring overwrites the array it plans on: a scratch one, not this transform's.
        double* scratch = fftw_alloc_real(n);
        if (scratch != nullptr) {
            plan = fftw_plan_r2r_1d(static_cast<int>(n), scratch, scratch, FFTW_RODFT00,
                                    measure ? FFTW_MEASURE : FFTW_ESTIMATE);
            fftw_free(scratch);
        }
        if (plan == nullptr) {
            plans().erase({n, measure});
            fftw_free(buffer_);
            throw std::runtime_error("FFTW could not plan a sine transform of length " + std::to_string(n));
        }
        if (measure) export_wisdom();
    }
    plan_ = plan;
    std::fill(buffer_, buffer_ + n, 0.0);
}

SineTransform::~SineTransform() {
    std::lock_guard lock(fftw_planner_mutex());
    fftw_free(buffer_);
}

double SineTransform::planned_flops() const {
    std::lock_guard lock(fftw_planner_mutex());
    return fftw_estimate_cost(static_cast<fftw_plan>(plan_));
}

void SineTransform::apply(std::span<const double> input, std::span<double> output, double scale) const {
    std::copy(input.begin(), input.end(), buffer_);
    fftw_execute_r2r(static_cast<fftw_plan>(plan_), buffer_, buffer_);
    std::transform(buffer_, buffer_ + n_, output.begin(), [scale](double y) { return scale * y; });
}

}  // namespace fretbuzz
