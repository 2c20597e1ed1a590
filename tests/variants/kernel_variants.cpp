// Every kernel's results over random inputs, as one 64-bit hash per kernel. The kernels are
// compiled for baseline x86-64, AVX2 and AVX-512 and the processor picks one at load time, so
// the same program run on an AVX-512 processor and under valgrind (whose virtual processor has
// AVX2 but not AVX-512) compares the AVX-512 variant with the AVX2 one bit for bit
// (compare.sh). `kernel_variants --level` prints the variant this processor runs.
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <string_view>
#include <vector>

#include "fretbuzz/scheme/Kernels.hpp"

namespace {
using namespace fretbuzz::kernels;

// FNV-1a over the bits of every double a kernel wrote or returned.
struct Hash {
    std::uint64_t h = 1469598103934665603ull;
    void add(double x) {
        std::uint64_t b;
        std::memcpy(&b, &x, sizeof b);
        h = (h ^ b) * 1099511628211ull;
    }
    void add(const std::vector<double>& v, std::size_t n) {
        for (std::size_t i = 0; i < n; ++i) add(v[i]);
    }
};

constexpr std::size_t kMax = 700;  // longer than a sitar's 439 modes; every remainder mod 8 appears
constexpr std::size_t kRows = 16;

struct Inputs {
    std::vector<double> e, beta, loss, q, d, impulse, x, w, s, qq, qd, dq, dd, aq, ad, c;
    std::vector<std::vector<double>> rows;
    std::vector<const double*> row_ptrs;
    std::size_t n = 0, m = 0;

    void draw(std::mt19937_64& g, std::size_t trial) {
        std::uniform_real_distribution<double> any(-1.0, 1.0), positive(0.5, 1.0);
        const auto fill = [&](std::vector<double>& v, bool pos) {
            v.resize(kMax);
            for (auto& y : v) y = pos ? positive(g) : any(g);
        };
        for (auto* v : {&e, &loss, &w, &s}) fill(*v, true);
        for (auto* v : {&beta, &q, &d, &impulse, &x, &qq, &qd, &dq, &dd, &aq, &ad}) fill(*v, false);
        c.resize(kRows);
        for (auto& y : c) y = any(g);
        rows.resize(kRows);
        row_ptrs.resize(kRows);
        for (std::size_t r = 0; r < kRows; ++r) {
            fill(rows[r], false);
            row_ptrs[r] = rows[r].data();
        }
        n = trial < 80 ? trial : static_cast<std::size_t>(g() % kMax);  // every short length, then any
        m = 1 + static_cast<std::size_t>(g() % kMaxRowsPerPass);
    }
};

// One kernel, run on one draw of inputs, its outputs added to the hash.
void run_kernel(int k, Inputs& in, std::mt19937_64& g, Hash& h) {
    const std::size_t n = in.n, m = in.m;
    double* q = in.q.data();
    double* d = in.d.data();
    const double* e = in.e.data();
    const double* beta = in.beta.data();
    std::vector<double> out(kRows, 0.0);
    double a = 0.0, b = 0.0;
    switch (k) {
        case 0: h.add(dot(q, d, n)); break;
        case 1: dot_rows(in.row_ptrs.data(), m, in.x.data(), n, out.data()); h.add(out, m); break;
        case 2: dot_current_previous(in.row_ptrs[0], q, d, n, a, b); h.add(a); h.add(b); break;
        case 3: predict(e, beta, q, d, in.x.data(), n); h.add(in.x, n); break;
        case 4: h.add(predict_dot(e, beta, q, d, in.row_ptrs[0], n)); break;
        case 5: predict_dot_rows(e, beta, q, d, in.row_ptrs.data(), m, n, out.data()); h.add(out, m); break;
        case 6: h.add(advance(e, beta, in.loss.data(), in.impulse.data(), q, d, n)); break;
        case 7: h.add(advance(e, beta, nullptr, nullptr, q, d, n)); break;
        case 8: h.add(advance_one_push(e, beta, in.loss.data(), in.c[0], in.row_ptrs[0], q, d, n)); break;
        case 9: {
            const std::size_t pushes = 1 + static_cast<std::size_t>(g() % 12);
            h.add(advance_pushes(e, beta, in.loss.data(), in.c.data(), in.row_ptrs.data(), pushes, q, d, n));
            break;
        }
        case 10:
        case 11: {  // the pass with products, plain and with a finger's pad
            const std::size_t pushes = static_cast<std::size_t>(g() % 12), predicted = static_cast<std::size_t>(g() % 12);
            std::vector<double> p(kRows, 0.0);
            double observed = 0.0, energy = 0.0;
            StepProducts products;
            products.predict_rows = in.row_ptrs.data() + 4;
            products.predict_count = predicted;
            products.predicted = p.data();
            if (g() % 2) {
                products.observe_row = in.row_ptrs[15];
                products.observed = &observed;
            }
            if (g() % 2) products.energy = &energy;
            const double* loss = g() % 3 ? in.loss.data() : nullptr;
            const auto pass = k == 10 ? advance_with_products : advance_with_pad_products;
            h.add(pass(e, beta, loss, in.c.data(), in.row_ptrs.data(), pushes, products, q, d, n));
            h.add(p, predicted);
            h.add(observed);
            h.add(energy);
            break;
        }
        case 12: h.add(modal_energy(e, beta, q, d, n)); break;
        case 13: {
            const std::size_t first = static_cast<std::size_t>(g() % (n + 1));
            h.add(jump_with_products(in.qq.data(), in.qd.data(), in.dq.data(), in.dd.data(), first, e, beta,
                                     in.row_ptrs.data(), m, q, d, n, out.data()));
            h.add(out, m);
            break;
        }
        case 14: free_amplitudes(in.aq.data(), in.ad.data(), q, d, in.x.data(), n); h.add(in.x, n); break;
        case 15: h.add(sum(in.x.data(), n)); break;
        case 16: h.add(weighted_abs_sum(in.w.data(), in.x.data(), n)); break;
        case 17: weighted_abs_sums(in.w.data(), in.s.data(), in.x.data(), n, a, b); h.add(a); h.add(b); break;
        case 18: axpy(in.c[0], in.x.data(), q, n); break;
        case 19: jump(in.qq.data(), in.qd.data(), in.dq.data(), in.dd.data(), q, d, n); break;
        default: break;
    }
    h.add(in.q, n);  // the state the kernels update in place
    h.add(in.d, n);
}

constexpr const char* kNames[] = {"dot", "dot_rows", "dot_current_previous", "predict", "predict_dot",
                                  "predict_dot_rows", "advance", "advance (lossless, no impulse)",
                                  "advance_one_push", "advance_pushes", "advance_with_products",
                                  "advance_with_pad_products", "modal_energy", "jump_with_products",
                                  "free_amplitudes", "sum", "weighted_abs_sum", "weighted_abs_sums", "axpy",
                                  "jump"};
}  // namespace

int main(int argc, char** argv) {
    if (argc > 1 && std::string_view(argv[1]) == "--level") {
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
        __builtin_cpu_init();
        std::puts(__builtin_cpu_supports("x86-64-v4") ? "x86-64-v4" : __builtin_cpu_supports("x86-64-v3") ? "x86-64-v3" : "x86-64");
#else
        std::puts("single");  // one variant only
#endif
        return 0;
    }
    for (int k = 0; k < static_cast<int>(std::size(kNames)); ++k) {
        std::mt19937_64 g(2017);  // each kernel sees the same draws whatever runs before it
        Inputs in;
        Hash h;
        for (std::size_t trial = 0; trial < 400; ++trial) {
            in.draw(g, trial);
            run_kernel(k, in, g, h);
        }
        std::printf("%-32s %016llx\n", kNames[k], static_cast<unsigned long long>(h.h));
    }
    return 0;
}
