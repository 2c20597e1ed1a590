#pragma once
// One polarisation's modal state over its plan's exact per-mode propagator, in difference form:
// q^n and d^n = q^n - q^{n-1}. It forms the free prediction of q^{n+1} (whole, or at a few rows
// on the fly), takes the exact free first step, and advances by one pass over the modes
// (kernels::StepPass): whatever pushes the string, and whatever reads the state the pass leaves,
// come in through that pass, so the state knows nothing of contacts. A string owns one per
// polarisation it steps this way; an assembly of strings (and a bridge's modes) would own one
// each.
#include <cstddef>
#include <span>
#include <vector>

#include "fretbuzz/numerics/CacheAligned.hpp"
#include "fretbuzz/numerics/Kernels.hpp"
#include "fretbuzz/scheme/ModalPropagator.hpp"
#include "fretbuzz/SubnormalFlush.hpp"

namespace fretbuzz {

class ModalState {
public:
    // At n = 0: modal displacement q0 and velocity v0 (dq/dt, read by the first step only).
    ModalState(const ModalPropagator& propagator, std::span<const double> q0, std::span<const double> v0);

    std::size_t size() const { return q_.size(); }
    const ModalPropagator& propagator() const { return *propagator_; }
    std::span<const double> q() const { return q_; }  // q^n
    std::span<const double> d() const { return d_; }  // q^n - q^{n-1}
    AlignedVector& q() { return q_; }
    AlignedVector& d() { return d_; }

    // n = 0 -> 1: the exact free motion of every mode from (q^0, v0).
    void first_step();
    // An external impulse between two steps: q^n += dq and q^{n-1} += dq - dv dt (before the
    // first step: q^0 += dq, v0 += dv).
    void perturb(std::span<const double> displacement, std::span<const double> velocity, bool started);
    void silence();  // q = d = v0 = 0

    // row . q^n, and row . q^n with row . q^{n-1}.
    double at(const double* row) const { return kernels::dot(row, q_.data(), q_.size()); }
    void at_both(const double* row, double& now, double& before) const {
        kernels::dot_current_previous(row, q_.data(), d_.data(), q_.size(), now, before);
    }
    // The free prediction of q^{n+1} into `out` (size N).
    void predict(std::span<double> out) const;
    // out[r] = rows[r] . (free q^{n+1}) for r < m, the prediction formed on the fly (not stored).
    void predict_at(const double* const* rows, std::size_t m, double* out) const;
    // One step: the plan's kernel on `pass`; returns the kernel's sum of the damping terms
    // (unscaled; 0 when lossless).
    double advance(kernels::StepKernel kernel, const kernels::StepPass& pass) {
        const ModalPropagator& prop = *propagator_;
        return kernel(prop.decay().data(), prop.beta().data(), prop.lossless() ? nullptr : prop.loss().data(), pass,
                      q_.data(), d_.data(), q_.size());
    }
    // Free flight: modes [first, first + count) one free step (no impulse).
    void step_modes(std::size_t first, std::size_t count);
    // The discrete modal energy times 2 dt^2 / mu (ModalPropagator::scaled_modal_energy).
    double scaled_energy() const { return propagator_->scaled_modal_energy(q_, d_); }
    // Coordinates (q, d, v0) that are subnormal: none where the stepping loop flushes them.
    std::size_t subnormal_coordinates() const {
        return subnormal_count(q_) + subnormal_count(d_) + subnormal_count(v0_);
    }

private:
    const ModalPropagator* propagator_;  // the plan's (its damping may change between steps)
    AlignedVector q_, d_;
    std::vector<double> v0_;
};

}  // namespace fretbuzz
