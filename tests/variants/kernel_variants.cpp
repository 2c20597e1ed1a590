// The kernels of one instruction-set level (tests/CMakeLists.txt builds this program with
// src/numerics/Kernels.cpp once per level: baseline x86-64, x86-64-v3 (AVX2) and x86-64-v4
// (AVX-512), each a program of its own, so that no code of one level runs on a processor without
// it). It writes every kernel's results over the same random inputs (`kernel_variant > file`);
// `kernel_variant --compare BASE OTHER` then says, kernel by kernel, how far the other level's
// results are from the baseline's (relative L2 over all of a kernel's outputs) and fails above
// the stated tolerance; `--levels` prints the levels this processor runs (compare.sh).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "fretbuzz/numerics/Kernels.hpp"

namespace {
using namespace fretbuzz::kernels;

// What a kernel returned or wrote, in order.
struct Outputs {
    std::vector<double> values;
    void add(double x) { values.push_back(x); }
    void add(const std::vector<double>& v, std::size_t n) { values.insert(values.end(), v.begin(), v.begin() + static_cast<long>(n)); }
};

// The tolerance the variants are held to (relative L2 over a kernel's outputs): they sum in the
// same order and differ only where one fuses a multiply-add (about 1e-16 here), so anything
// near it is a defect.
constexpr double kTolerance = 1e-12;

constexpr std::size_t kMax = 700;  // longer than a sitar's 439 modes; every remainder mod 8 appears
constexpr std::size_t kRows = 16;
constexpr std::size_t kTrials = 200;

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
// writes to the outputs (main adds the state q, d that the kernels update in place).
struct Kernel {
    const char* name;
    void (*run)(Inputs& in, std::mt19937_64& g, Outputs& h);
};

// The step's pass: any counts of pushes (rows, or an impulse vector) and predicted rows, with or
// without the observation and the energy.
template <auto Step>
void run_pass(Inputs& in, std::mt19937_64& g, Outputs& h) {
    const std::size_t pushes = static_cast<std::size_t>(g() % 17), predicted = static_cast<std::size_t>(g() % 17);
    std::vector<double> p(kRows, 0.0);
    double observed = 0.0, energy = 0.0;
    StepPass pass;
    if (g() % 4 == 0) {
        pass.impulse = in.impulse.data();
    } else {
        pass.push_rows = in.row_ptrs.data();
        pass.push_coefficients = in.c.data();
        pass.pushes = pushes;
    }
    pass.predict_rows = in.row_ptrs.data();
    pass.predict_count = predicted;
    pass.predicted = p.data();
    if (g() % 2) {
        pass.observe_row = in.row_ptrs[15];
        pass.observed = &observed;
    }
    if (g() % 2) pass.energy = &energy;
    h.add(Step(in.e.data(), in.beta.data(), in.loss.data(), pass, in.q.data(), in.d.data(), in.n));
    h.add(p, predicted);
    h.add(observed);
    h.add(energy);
}

const Kernel kKernels[] = {
    {"dot", [](Inputs& in, std::mt19937_64&, Outputs& h) { h.add(dot(in.q.data(), in.d.data(), in.n)); }},
    {"dot_rows",
     [](Inputs& in, std::mt19937_64&, Outputs& h) {
         std::vector<double> out(kRows, 0.0);
         dot_rows(in.row_ptrs.data(), in.m, in.x.data(), in.n, out.data());
         h.add(out, in.m);
     }},
    {"dot_current_previous",
     [](Inputs& in, std::mt19937_64&, Outputs& h) {
         double current = 0.0, previous = 0.0;
         dot_current_previous(in.row_ptrs[0], in.q.data(), in.d.data(), in.n, current, previous);
         h.add(current);
         h.add(previous);
     }},
    {"predict",
     [](Inputs& in, std::mt19937_64&, Outputs& h) {
         predict(in.e.data(), in.beta.data(), in.q.data(), in.d.data(), in.x.data(), in.n);
         h.add(in.x, in.n);
     }},
    {"predict_dot_rows",
     [](Inputs& in, std::mt19937_64&, Outputs& h) {
         std::vector<double> out(kRows, 0.0);
         predict_dot_rows(in.e.data(), in.beta.data(), in.q.data(), in.d.data(), in.row_ptrs.data(), in.m, in.n,
                          out.data());
         h.add(out, in.m);
     }},
    {"advance",
     [](Inputs& in, std::mt19937_64&, Outputs& h) {
         h.add(advance(in.e.data(), in.beta.data(), in.loss.data(), in.impulse.data(), in.q.data(), in.d.data(), in.n));
     }},
    {"advance (lossless, no impulse)",
     [](Inputs& in, std::mt19937_64&, Outputs& h) {
         h.add(advance(in.e.data(), in.beta.data(), nullptr, nullptr, in.q.data(), in.d.data(), in.n));
     }},
    {"step_lossy", run_pass<step_lossy>},
    {"step_lossless", run_pass<step_lossless>},
    {"modal_energy",
     [](Inputs& in, std::mt19937_64&, Outputs& h) {
         h.add(modal_energy(in.e.data(), in.beta.data(), in.q.data(), in.d.data(), in.n));
     }},
    {"jump_with_products",
     [](Inputs& in, std::mt19937_64& g, Outputs& h) {
         std::vector<double> out(kRows, 0.0);
         const std::size_t first = static_cast<std::size_t>(g() % (in.n + 1));
         h.add(jump_with_products(in.qq.data(), in.qd.data(), in.dq.data(), in.dd.data(), first, in.e.data(),
                                  in.beta.data(), in.row_ptrs.data(), in.m, in.q.data(), in.d.data(), in.n,
                                  out.data()));
         h.add(out, in.m);
     }},
    {"free_amplitudes",
     [](Inputs& in, std::mt19937_64&, Outputs& h) {
         free_amplitudes(in.aq.data(), in.ad.data(), in.q.data(), in.d.data(), in.x.data(), in.n);
         h.add(in.x, in.n);
     }},
    {"sum", [](Inputs& in, std::mt19937_64&, Outputs& h) { h.add(sum(in.x.data(), in.n)); }},
    {"weighted_abs_sum",
     [](Inputs& in, std::mt19937_64&, Outputs& h) { h.add(weighted_abs_sum(in.w.data(), in.x.data(), in.n)); }},
    {"weighted_abs_sums",
     [](Inputs& in, std::mt19937_64&, Outputs& h) {
         double by_w = 0.0, by_s = 0.0;
         weighted_abs_sums(in.w.data(), in.s.data(), in.x.data(), in.n, by_w, by_s);
         h.add(by_w);
         h.add(by_s);
     }},
    {"axpy", [](Inputs& in, std::mt19937_64&, Outputs&) { axpy(in.c[0], in.x.data(), in.q.data(), in.n); }},
    {"jump",
     [](Inputs& in, std::mt19937_64&, Outputs&) {
         jump(in.qq.data(), in.qd.data(), in.dq.data(), in.dd.data(), in.q.data(), in.d.data(), in.n);
     }},
};

void write(std::ostream& out) {
    for (const Kernel& kernel : kKernels) {
        std::mt19937_64 g(2017);  // each kernel sees the same draws whatever runs before it
        Inputs in;
        Outputs h;
        for (std::size_t trial = 0; trial < kTrials; ++trial) {
            in.draw(g, trial);
            kernel.run(in, g, h);
            h.add(in.q, in.n);  // the state the kernels update in place
            h.add(in.d, in.n);
        }
        const std::uint64_t count = h.values.size();
        out << kernel.name << '\n';
        out.write(reinterpret_cast<const char*>(&count), sizeof count);
        out.write(reinterpret_cast<const char*>(h.values.data()), static_cast<std::streamsize>(count * sizeof(double)));
    }
}

bool read(std::istream& in, std::string& name, std::vector<double>& values) {
    std::uint64_t count = 0;
    if (!std::getline(in, name) || !in.read(reinterpret_cast<char*>(&count), sizeof count) || count > (1u << 26))
        return false;
    values.resize(count);
    return static_cast<bool>(in.read(reinterpret_cast<char*>(values.data()), static_cast<std::streamsize>(count * sizeof(double))));
}

int compare(const char* base_path, const char* other_path) {
    std::ifstream base(base_path, std::ios::binary), other(other_path, std::ios::binary);
    int failed = 0, compared = 0;
    std::string name, other_name;
    std::vector<double> x, y;
    while (read(base, name, x)) {
        if (!read(other, other_name, y) || other_name != name || y.size() != x.size()) {
            std::printf("%s: missing or of another size in %s\n", name.c_str(), other_path);
            return 1;
        }
        double diff = 0.0, norm = 0.0;
        for (std::size_t i = 0; i < x.size(); ++i) {
            diff += (x[i] - y[i]) * (x[i] - y[i]);
            norm += x[i] * x[i];
        }
        const double relative = norm > 0.0 ? std::sqrt(diff / norm) : std::sqrt(diff);
        const bool ok = relative <= kTolerance;  // (false for NaN)
        std::printf("%-32s relative L2 %.3e%s\n", name.c_str(), relative, ok ? "" : "  ABOVE THE TOLERANCE");
        failed += ok ? 0 : 1;
        ++compared;
    }
    if (compared != static_cast<int>(std::size(kKernels))) {
        std::printf("read %d kernels of %zu from %s\n", compared, std::size(kKernels), base_path);
        return 1;
    }
    return failed == 0 ? 0 : 1;
}
}  // namespace

int main(int argc, char** argv) {
    if (argc > 1 && std::string_view(argv[1]) == "--levels") {
#if defined(__x86_64__) && defined(__GNUC__)
        __builtin_cpu_init();
        std::puts(__builtin_cpu_supports("x86-64-v4")   ? "x86-64 x86-64-v3 x86-64-v4"
                  : __builtin_cpu_supports("x86-64-v3") ? "x86-64 x86-64-v3"
                                                        : "x86-64");
#else
        std::puts("single");  // one variant only
#endif
        return 0;
    }
    if (argc == 4 && std::string_view(argv[1]) == "--compare") return compare(argv[2], argv[3]);
    write(std::cout);
    return std::cout ? 0 : 1;
}
