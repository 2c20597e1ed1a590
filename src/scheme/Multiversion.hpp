#pragma once
// FRETBUZZ_MULTIVERSION: a function compiled twice, for baseline x86-64 and for AVX2 (x86-64-v3),
// the processor choosing at load time. GCC contracts a * b + c into a fused multiply-add in C++
// even in ISO mode (-ffp-contract=fast is its C++ default), so a variant that multiplies and adds
// may differ from the other in the last bits; moves and lone products do not.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define FRETBUZZ_MULTIVERSION __attribute__((target_clones("default", "arch=x86-64-v3")))
#else
#define FRETBUZZ_MULTIVERSION
#endif
