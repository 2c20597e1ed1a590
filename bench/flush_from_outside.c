/* Preloaded into a fretbuzz program (LD_PRELOAD), this sets flush-to-zero and
 * denormals-are-zero before main(), so that the whole process, and every thread it
 * starts (a new thread inherits its creator's floating-point control), computes without
 * subnormal numbers whatever the program itself does. It is the yardstick of issue 54's
 * target: a build's own guard is judged against the same binary flushed from outside.
 *   LD_PRELOAD=build/bench/libfretbuzz_flush_from_outside.so build/cli/fretbuzz run bass-pop */
#if defined(__x86_64__)
#include <xmmintrin.h>
static void __attribute__((constructor)) flush_subnormals(void) {
    _mm_setcsr(_mm_getcsr() | 0x8040u); /* FTZ (bit 15) and DAZ (bit 6) */
}
#elif defined(__aarch64__)
static void __attribute__((constructor)) flush_subnormals(void) {
    unsigned long fpcr;
    __asm__ volatile("mrs %0, fpcr" : "=r"(fpcr));
    fpcr |= 1ul << 24; /* FZ */
    __asm__ volatile("msr fpcr, %0" : : "r"(fpcr));
}
#endif
