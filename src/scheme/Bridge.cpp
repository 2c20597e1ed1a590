#include "fretbuzz/scheme/Bridge.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <numbers>

#include "fretbuzz/numerics/Kernels.hpp"

namespace fretbuzz {

namespace {

ModeTable bridge_table(std::span<const BridgeModeSpec> modes) {
    ModeTable table;
    for (const BridgeModeSpec& m : modes) {
        table.frequency_hz.push_back(m.frequency_hz);
        table.sigma_per_s.push_back(m.damping_ratio * 2.0 * std::numbers::pi * m.frequency_hz);
        table.source.push_back(ModeSource::model);
    }
    return table;
}

}  // namespace

Bridge::Bridge(std::span<const BridgeModeSpec> modes, std::span<const double> end_stiffness, double dt)
    : propagator_(std::make_shared<const ModalPropagator>(bridge_table(modes), dt)),
      state_(*propagator_, std::vector<double>(modes.size(), 0.0), std::vector<double>(modes.size(), 0.0)),
      stiffness_(end_stiffness.begin(), end_stiffness.end()),
      end_now_(end_stiffness.size(), 0.0),
      end_before_(end_stiffness.size(), 0.0),
      predicted_(modes.size()),
      rhs_(modes.size()),
      impulse_(modes.size()),
      dt_(dt) {
    const std::size_t B = modes.size(), S = stiffness_.size();
    share_.assign(S * B, 0.0);
    for (std::size_t b = 0; b < B; ++b) {
        root_mass_.push_back(std::sqrt(modes[b].mass_kg));
        for (std::size_t s = 0; s < S; ++s) share_[s * B + b] = modes[b].participation[s] / root_mass_[b];
    }
    const auto n = static_cast<Eigen::Index>(B);
    Eigen::MatrixXd a = Eigen::MatrixXd::Identity(n, n) / (dt * dt);
    for (std::size_t s = 0; s < S; ++s) {
        const Eigen::Map<const Eigen::VectorXd> p(share_.data() + s * B, n);
        a += 0.5 * stiffness_[s] * p * p.transpose();
    }
    const Eigen::MatrixXd inverse = a.llt().solve(Eigen::MatrixXd::Identity(n, n));
    inverse_.assign(inverse.data(), inverse.data() + B * B);  // symmetric: either order
}

void Bridge::step(std::span<const double> pull) {
    const std::size_t B = size(), S = strings();
    state_.predict(predicted_);
    const double rate = 1.0 / (dt_ * dt_);
    for (std::size_t b = 0; b < B; ++b) rhs_[b] = rate * predicted_[b];
    for (std::size_t s = 0; s < S; ++s) {
        const double f = pull[s] - 0.5 * stiffness_[s] * end_before_[s];
        kernels::axpy(f, share_.data() + s * B, rhs_.data(), B);
    }
    for (std::size_t b = 0; b < B; ++b)
        impulse_[b] = kernels::dot(inverse_.data() + b * B, rhs_.data(), B) - predicted_[b];
    const ModalPropagator& prop = *propagator_;
    const double losses = kernels::advance(prop.decay().data(), prop.beta().data(),
                                           prop.lossless() ? nullptr : prop.loss().data(), impulse_.data(),
                                           state_.q().data(), state_.d().data(), B);
    damping_ += losses / (4.0 * dt_ * dt_);
    for (std::size_t s = 0; s < S; ++s) {
        end_before_[s] = end_now_[s];
        end_now_[s] = kernels::dot(share_.data() + s * B, state_.q().data(), B);
    }
}

double Bridge::energy() const { return state_.scaled_energy() / (2.0 * dt_ * dt_); }

double Bridge::velocity() const {
    double v = 0.0;
    for (std::size_t b = 0; b < size(); ++b) v += state_.d()[b] / root_mass_[b];
    return v / dt_;
}

}  // namespace fretbuzz
