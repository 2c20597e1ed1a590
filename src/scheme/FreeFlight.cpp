#include "fretbuzz/scheme/FreeFlight.hpp"

#include "fretbuzz/numerics/Kernels.hpp"

namespace fretbuzz {

namespace {
// A 2x2 matrix held as I + E: for low modes the map is the identity plus something of
// order (omega dt)^2, which would drown in round-off if the identity were added in.
struct NearIdentity {
    double a, b, c, d;  // E = [[a, b], [c, d]]
    NearIdentity operator*(const NearIdentity& o) const {  // (I + E)(I + F) = I + E + F + E F
        return {a + o.a + (a * o.a + b * o.c), b + o.b + (a * o.b + b * o.d), c + o.c + (c * o.a + d * o.c),
                d + o.d + (c * o.b + d * o.d)};
    }
};
}  // namespace

FreeFlight::FreeFlight(const ModalPropagator& propagator, long steps, std::size_t first) : steps_(steps), first_(first) {
    const std::size_t n = propagator.size();
    qq_.resize(n);
    qd_.resize(n);
    dq_.resize(n);
    dd_.resize(n);
    update(propagator);
}

void FreeFlight::update(const ModalPropagator& propagator) {
    const std::size_t n = propagator.size();
    const long steps = steps_;
    const std::size_t first = first_;
    const auto e = propagator.decay();
    const auto beta = propagator.beta();
    const auto loss = propagator.loss();  // 1 - e, without cancellation
    for (std::size_t j = first; j < n; ++j) {
        // Powers by squaring: log2(M) products, each exact to a few ulps.
        NearIdentity power{0.0, 0.0, 0.0, 0.0};
        NearIdentity base{-beta[j], e[j], -beta[j], -loss[j]};
        for (long m = steps; m > 0; m >>= 1) {
            if (m & 1) power = power * base;
            base = base * base;
        }
        qq_[j] = power.a;
        qd_[j] = power.b;
        dq_[j] = power.c;
        dd_[j] = power.d;
    }
}

void FreeFlight::jump(std::span<double> q, std::span<double> d, std::size_t first) const {
    // Entries hold E of P^M = I + E: q gains E_qq q + E_qd d, d becomes E_dq q + (1 + E_dd) d.
    const std::size_t n = q.size() - first;
    kernels::jump(qq_.data() + first, qd_.data() + first, dq_.data() + first, dd_.data() + first, q.data() + first,
                  d.data() + first, n);
}

double FreeFlight::jump_with_products(std::span<double> q, std::span<double> d, std::size_t first,
                                      const ModalPropagator& propagator, std::span<const double* const> rows,
                                      double* out) const {
    return kernels::jump_with_products(qq_.data(), qd_.data(), dq_.data(), dd_.data(), first, propagator.decay().data(),
                                       propagator.beta().data(), rows.data(), rows.size(), q.data(), d.data(),
                                       q.size(), out);
}

}  // namespace fretbuzz
