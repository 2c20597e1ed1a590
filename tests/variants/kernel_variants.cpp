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

// One kernel: its name, and how it runs on one draw of inputs, adding what it returns or
// writes to the hash (main adds the state q, d that the kernels update in place).
struct Kernel {
    const char* name;
    void (*run)(Inputs& in, std::mt19937_64& g, Hash& h);
};

// The pass with products, plain or with a finger's pad: any counts of pushes and predicted rows,
// with or without the observation, the energy and the losses.
template <auto Pass>
void run_pass(Inputs& in, std::mt19937_64& g, Hash& h) {
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
    h.add(Pass(in.e.data(), in.beta.data(), loss, in.c.data(), in.row_ptrs.data(), pushes, products, in.q.data(),
               in.d.data(), in.n));
    h.add(p, predicted);
    h.add(observed);
    h.add(energy);
}

const Kernel kKernels[] = {
    {"dot", [](Inputs& in, std::mt19937_64&, Hash& h) { h.add(dot(in.q.data(), in.d.data(), in.n)); }},
    {"dot_rows",
     [](Inputs& in, std::mt19937_64&, Hash& h) {
         std::vector<double> out(kRows, 0.0);
         dot_rows(in.row_ptrs.data(), in.m, in.x.data(), in.n, out.data());
         h.add(out, in.m);
     }},
    {"dot_current_previous",
     [](Inputs& in, std::mt19937_64&, Hash& h) {
         double current = 0.0, previous = 0.0;
         dot_current_previous(in.row_ptrs[0], in.q.data(), in.d.data(), in.n, current, previous);
         h.add(current);
         h.add(previous);
     }},
    {"predict",
     [](Inputs& in, std::mt19937_64&, Hash& h) {
         predict(in.e.data(), in.beta.data(), in.q.data(), in.d.data(), in.x.data(), in.n);
         h.add(in.x, in.n);
     }},
    {"predict_dot",
     [](Inputs& in, std::mt19937_64&, Hash& h) {
         h.add(predict_dot(in.e.data(), in.beta.data(), in.q.data(), in.d.data(), in.row_ptrs[0], in.n));
     }},
    {"predict_dot_rows",
     [](Inputs& in, std::mt19937_64&, Hash& h) {
         std::vector<double> out(kRows, 0.0);
         predict_dot_rows(in.e.data(), in.beta.data(), in.q.data(), in.d.data(), in.row_ptrs.data(), in.m, in.n,
                          out.data());
         h.add(out, in.m);
     }},
    {"advance",
     [](Inputs& in, std::mt19937_64&, Hash& h) {
         h.add(advance(in.e.data(), in.beta.data(), in.loss.data(), in.impulse.data(), in.q.data(), in.d.data(), in.n));
     }},
    {"advance (lossless, no impulse)",
     [](Inputs& in, std::mt19937_64&, Hash& h) {
         h.add(advance(in.e.data(), in.beta.data(), nullptr, nullptr, in.q.data(), in.d.data(), in.n));
     }},
    {"advance_one_push",
     [](Inputs& in, std::mt19937_64&, Hash& h) {
         h.add(advance_one_push(in.e.data(), in.beta.data(), in.loss.data(), in.c[0], in.row_ptrs[0], in.q.data(),
                                in.d.data(), in.n));
     }},
    {"advance_pushes",
     [](Inputs& in, std::mt19937_64& g, Hash& h) {
         const std::size_t pushes = 1 + static_cast<std::size_t>(g() % 12);
         h.add(advance_pushes(in.e.data(), in.beta.data(), in.loss.data(), in.c.data(), in.row_ptrs.data(), pushes,
                              in.q.data(), in.d.data(), in.n));
     }},
    {"advance_with_products", run_pass<advance_with_products>},
    {"advance_with_pad_products", run_pass<advance_with_pad_products>},
    {"modal_energy",
     [](Inputs& in, std::mt19937_64&, Hash& h) {
         h.add(modal_energy(in.e.data(), in.beta.data(), in.q.data(), in.d.data(), in.n));
     }},
    {"jump_with_products",
     [](Inputs& in, std::mt19937_64& g, Hash& h) {
         std::vector<double> out(kRows, 0.0);
         const std::size_t first = static_cast<std::size_t>(g() % (in.n + 1));
         h.add(jump_with_products(in.qq.data(), in.qd.data(), in.dq.data(), in.dd.data(), first, in.e.data(),
                                  in.beta.data(), in.row_ptrs.data(), in.m, in.q.data(), in.d.data(), in.n,
                                  out.data()));
         h.add(out, in.m);
     }},
    {"free_amplitudes",
     [](Inputs& in, std::mt19937_64&, Hash& h) {
         free_amplitudes(in.aq.data(), in.ad.data(), in.q.data(), in.d.data(), in.x.data(), in.n);
         h.add(in.x, in.n);
     }},
    {"sum", [](Inputs& in, std::mt19937_64&, Hash& h) { h.add(sum(in.x.data(), in.n)); }},
    {"weighted_abs_sum",
     [](Inputs& in, std::mt19937_64&, Hash& h) { h.add(weighted_abs_sum(in.w.data(), in.x.data(), in.n)); }},
    {"weighted_abs_sums",
     [](Inputs& in, std::mt19937_64&, Hash& h) {
         double by_w = 0.0, by_s = 0.0;
         weighted_abs_sums(in.w.data(), in.s.data(), in.x.data(), in.n, by_w, by_s);
         h.add(by_w);
         h.add(by_s);
     }},
    {"axpy", [](Inputs& in, std::mt19937_64&, Hash&) { axpy(in.c[0], in.x.data(), in.q.data(), in.n); }},
    {"jump",
     [](Inputs& in, std::mt19937_64&, Hash&) {
         jump(in.qq.data(), in.qd.data(), in.dq.data(), in.dd.data(), in.q.data(), in.d.data(), in.n);
     }},
};
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
    for (const Kernel& kernel : kKernels) {
        std::mt19937_64 g(2017);  // each kernel sees the same draws whatever runs before it
        Inputs in;
        Hash h;
        for (std::size_t trial = 0; trial < 400; ++trial) {
            in.draw(g, trial);
            kernel.run(in, g, h);
            h.add(in.q, in.n);  // the state the kernels update in place
            h.add(in.d, in.n);
        }
        std::printf("%-32s %016llx\n", kernel.name, static_cast<unsigned long long>(h.h));
    }
    return 0;
}
