#include "fretbuzz/scheme/ModalState.hpp"

#include <algorithm>
#include <utility>

namespace fretbuzz {

ModalState::ModalState(const ModalPropagator& propagator, std::span<const double> q0, std::span<const double> v0)
    : propagator_(&propagator), q_(q0.begin(), q0.end()), d_(q0.size(), 0.0), v0_(v0.begin(), v0.end()) {}

void ModalState::first_step() {
    AlignedVector q1(q_.size());
    propagator_->first_step(q_, v0_, q1, d_);
    q_ = std::move(q1);
}

void ModalState::perturb(std::span<const double> displacement, std::span<const double> velocity, bool started) {
    const double dt = propagator_->dt();
    if (!started) {
        for (std::size_t j = 0; j < q_.size(); ++j) {
            q_[j] += displacement[j];
            v0_[j] += velocity[j];
        }
        return;
    }
    for (std::size_t j = 0; j < q_.size(); ++j) {
        q_[j] += displacement[j];
        d_[j] += velocity[j] * dt;
    }
}

void ModalState::silence() {
    std::fill(q_.begin(), q_.end(), 0.0);
    std::fill(d_.begin(), d_.end(), 0.0);
    std::fill(v0_.begin(), v0_.end(), 0.0);
}

void ModalState::predict(std::span<double> out) const {
    const ModalPropagator& prop = *propagator_;
    kernels::predict(prop.decay().data(), prop.beta().data(), q_.data(), d_.data(), out.data(), q_.size());
}

void ModalState::predict_at(const double* const* rows, std::size_t m, double* out) const {
    const ModalPropagator& prop = *propagator_;
    kernels::predict_dot_rows(prop.decay().data(), prop.beta().data(), q_.data(), d_.data(), rows, m, q_.size(), out);
}

void ModalState::step_modes(std::size_t first, std::size_t count) {
    const ModalPropagator& prop = *propagator_;
    kernels::advance(prop.decay().data() + first, prop.beta().data() + first, nullptr, nullptr, q_.data() + first,
                     d_.data() + first, count);
}

}  // namespace fretbuzz
