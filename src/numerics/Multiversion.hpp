#pragma once
// FRETBUZZ_MULTIVERSION: a function compiled three times, for baseline x86-64, for AVX2
// (x86-64-v3) and for AVX-512 (x86-64-v4), the processor choosing at load time: the one way
// the library picks code by processor. The variants sum in the same order but round
// differently where the compiler fuses multiply-adds (the AVX2 and AVX-512 ones have FMA):
// their results agree to round-off, and tests/variants checks it within a stated tolerance.
// A build may define the macro empty (one variant, for the -march it is compiled with): that
// test does.
#ifndef FRETBUZZ_MULTIVERSION
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define FRETBUZZ_MULTIVERSION __attribute__((target_clones("default", "arch=x86-64-v3", "arch=x86-64-v4")))
#else
#define FRETBUZZ_MULTIVERSION
#endif
#endif
