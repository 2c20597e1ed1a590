#pragma once
// The exact M-step map of every free mode, [q; d]^{n+M} = P_j^M [q; d]^n, with
// P_j = [[1 - beta_j, e_j], [-beta_j, e_j]] the one-step map in difference form. When no
// point can touch the obstacle for M steps, the string jumps over them in O(N) instead of
// O(N M): the result is the same free motion, to round-off.
#include <cstddef>
#include <span>
#include <vector>

#include "fretbuzz/numerics/CacheAligned.hpp"

#include "fretbuzz/scheme/ModalPropagator.hpp"

namespace fretbuzz {

// A flight checks sleeping points with its low modes plus a bound on the rest: at least this
// many modes (the driver's own band may ask for more) keep those checks sharp.
inline constexpr std::size_t kMinimumFlightModes = 48;

class FreeFlight {
public:
    // Maps for modes [first, N) (the others are left to the caller).
    FreeFlight(const ModalPropagator& propagator, long steps, std::size_t first = 0);

    long steps() const { return steps_; }
    std::size_t first() const { return first_; }  // the first mode it maps
    // Recomputes the maps after the propagator changed (same size; allocates nothing).
    void update(const ModalPropagator& propagator);
    // Applies the M-step map to modes [first, end) of (q, d).
    void jump(std::span<double> q, std::span<double> d, std::size_t first) const;
    // jump, and in the same pass over all modes what the state it leaves is read for:
    // out[r] = dot(rows[r], q) and the returned propagator.scaled_modal_energy(q, d), to
    // round-off (kernels::jump_with_products).
    double jump_with_products(std::span<double> q, std::span<double> d, std::size_t first,
                              const ModalPropagator& propagator, std::span<const double* const> rows,
                              double* out) const;

private:
    long steps_;
    std::size_t first_;
    AlignedVector qq_, qd_, dq_, dd_;  // P_j^M - I
};

}  // namespace fretbuzz
