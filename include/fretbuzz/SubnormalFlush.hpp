#pragma once
// Subnormal numbers flushed to zero on this thread while a SubnormalFlush lives (and put back as
// they were when it ends). A decaying string's high modes sink below 2.2e-308 within a second or
// two; from there on every product on them is a subnormal, which many processors (Intel's among
// them) compute in microcode at about a hundred times the cost. Zero is what the physics has
// there: a mode at 1e-308 m is 300 orders of magnitude below anything heard or measured, so
// every output keeps its value to round-off (docs/architecture.md, "Subnormal numbers").
//
// Every loop that steps strings holds one for its whole length, on whichever thread runs it
// (a worker of the set-up bench, a sweep's thread, a thread the Python interpreter made): the
// floating-point mode is per thread, so a guard set once in main would not reach them.
//   x86-64: MXCSR's FTZ (results) and DAZ (inputs) bits.   AArch64: FPCR.FZ (both).
// Elsewhere it does nothing, and active() says so.
#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>

#if defined(__x86_64__) || defined(_M_X64) || defined(__SSE2__)
#include <xmmintrin.h>
#define FRETBUZZ_FLUSH_MXCSR 1
#elif defined(__aarch64__)
#define FRETBUZZ_FLUSH_FPCR 1
#endif

namespace fretbuzz {

class SubnormalFlush {
public:
    SubnormalFlush() noexcept : saved_(read()) { write(saved_ | kFlushBits); }
    ~SubnormalFlush() { write(saved_); }
    SubnormalFlush(const SubnormalFlush&) = delete;
    SubnormalFlush& operator=(const SubnormalFlush&) = delete;

    // Whether this thread flushes subnormals now (false where the processor has no such mode).
    static bool active() noexcept { return kFlushBits != 0 && (read() & kFlushBits) == kFlushBits; }

private:
#if defined(FRETBUZZ_FLUSH_MXCSR)
    static constexpr std::uint64_t kFlushBits = 0x8040u;  // FTZ (bit 15) | DAZ (bit 6)
    static std::uint64_t read() noexcept { return _mm_getcsr(); }
    static void write(std::uint64_t v) noexcept { _mm_setcsr(static_cast<unsigned>(v)); }
#elif defined(FRETBUZZ_FLUSH_FPCR)
    static constexpr std::uint64_t kFlushBits = std::uint64_t{1} << 24;  // FZ
    static std::uint64_t read() noexcept {
        std::uint64_t v;
        __asm__ __volatile__("mrs %0, fpcr" : "=r"(v));
        return v;
    }
    static void write(std::uint64_t v) noexcept { __asm__ __volatile__("msr fpcr, %0" : : "r"(v)); }
#else
    static constexpr std::uint64_t kFlushBits = 0;
    static std::uint64_t read() noexcept { return 0; }
    static void write(std::uint64_t) noexcept {}
#endif
    std::uint64_t saved_;
};

// How many of `values` are subnormal (from their bits: a comparison would read them as zero
// where subnormal inputs are flushed).
inline std::size_t subnormal_count(std::span<const double> values) noexcept {
    std::size_t n = 0;
    for (const double v : values) {
        const std::uint64_t bits = std::bit_cast<std::uint64_t>(v);
        n += (bits & 0x7ff0000000000000u) == 0 && (bits & 0x000fffffffffffffu) != 0;
    }
    return n;
}

}  // namespace fretbuzz
