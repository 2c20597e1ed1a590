#pragma once
// FRETBUZZ_MULTIVERSION: a function compiled three times, for baseline x86-64, for AVX2
// (x86-64-v3) and for AVX-512 (x86-64-v4), the processor choosing at load time. GCC contracts
// a * b + c into a fused multiply-add in C++ even in ISO mode (-ffp-contract=fast is its C++
// default), so the baseline variant (no FMA) may differ from the others in the last bits. The
// AVX2 and AVX-512 variants give the same bits: the kernels fix their sums' order and which
// products are fused in the source (vector types, explicit remainders), and
// tests/variants/kernel_variants checks it under a CPU without AVX-512.
// FRETBUZZ_MULTIVERSION_AVX2 is for a loop whose fusing GCC chooses differently for AVX-512:
// it has no AVX-512 variant.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define FRETBUZZ_MULTIVERSION __attribute__((target_clones("default", "arch=x86-64-v3", "arch=x86-64-v4")))
#define FRETBUZZ_MULTIVERSION_AVX2 __attribute__((target_clones("default", "arch=x86-64-v3")))
#else
#define FRETBUZZ_MULTIVERSION
#define FRETBUZZ_MULTIVERSION_AVX2
#endif
