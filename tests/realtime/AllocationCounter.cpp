#include "AllocationCounter.hpp"

#include <unistd.h>

#include <cstddef>
#include <cstdlib>

// glibc's own entry points: the replacements below count, then forward to them.
extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* p, std::size_t size);
void* __libc_memalign(std::size_t alignment, std::size_t size);
}

namespace {
thread_local bool counting = false;
thread_local long counted = 0;
inline void note() {
    if (!counting) return;
    ++counted;
    static const bool abort_now = std::getenv("FRETBUZZ_ABORT_ON_ALLOCATION") != nullptr;
    if (abort_now) std::abort();  // for a debugger's backtrace
}
}  // namespace

extern "C" {
void* malloc(std::size_t size) {
    note();
    return __libc_malloc(size);
}
void* calloc(std::size_t count, std::size_t size) {
    note();
    return __libc_calloc(count, size);
}
void* realloc(void* p, std::size_t size) {
    note();
    return __libc_realloc(p, size);
}
void* aligned_alloc(std::size_t alignment, std::size_t size) {
    note();
    return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t size) {
    note();
    *out = __libc_memalign(alignment, size);
    return *out == nullptr ? 12 : 0;  // ENOMEM
}
// The older aligned allocators (FFTW's fftw_malloc may use memalign).
void* memalign(std::size_t alignment, std::size_t size) {
    note();
    return __libc_memalign(alignment, size);
}
void* valloc(std::size_t size) {
    note();
    return __libc_memalign(static_cast<std::size_t>(sysconf(_SC_PAGESIZE)), size);
}
void* pvalloc(std::size_t size) {
    note();
    const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
    return __libc_memalign(page, (size + page - 1) / page * page);
}
}

namespace fretbuzz::testing {

long allocations() { return counted; }
Counting::Counting() { counting = true; }
Counting::~Counting() { counting = false; }

}  // namespace fretbuzz::testing
