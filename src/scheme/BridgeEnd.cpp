#include "fretbuzz/scheme/BridgeEnd.hpp"

#include "fretbuzz/numerics/Kernels.hpp"

namespace fretbuzz {

BridgeEnd::BridgeEnd(const Plan& plan, const StringProperties& string)
    : plan_(&plan),
      g_(plan.mode_count()),
      shapes_(2, std::vector<double>(plan.mode_count(), 0.0)),
      first_gesture_(plan.forces().size()),
      g_loss_(plan.mode_count(), 0.0),
      mu_(plan.linear_density()),
      dt_(plan.dt()),
      stiffness_(string.tension_n / string.length_m),
      q_(plan.mode_count()),
      d_(plan.mode_count()) {
    const ModalBasis& basis = plan.basis();
    const std::size_t n = plan.mode_count();
    std::vector<double> psi(n);
    for (std::size_t i = 0; i < n; ++i) psi[i] = static_cast<double>(i + 1) * basis.grid_step() / basis.length();
    basis.to_modes(psi, g_);
    g_norm2_ = kernels::dot(g_.data(), g_.data(), n);
    form_loads();
}

void BridgeEnd::form_loads() {
    // In place (a damping changed while a voice plays allocates nothing).
    const std::size_t n = g_.size();
    const ModalPropagator& prop = plan_->propagator();
    const double k = plan_->force_to_displacement();
    lossy_ = !prop.lossless();
    for (std::size_t j = 0; j < n; ++j) {
        const double loss = lossy_ ? 1.0 - prop.decay()[j] : 0.0;
        shapes_[0][j] = g_[j] * (prop.beta()[j] + loss) / k;  // 2 - A = beta + 1 - e
        shapes_[1][j] = g_[j] * loss / k;
        g_loss_[j] = g_[j] * loss;
    }
    load_now_ = k * kernels::dot(g_.data(), shapes_[0].data(), n);
    load_before_ = k * kernels::dot(g_.data(), shapes_[1].data(), n);
    loss_norm_ = kernels::dot(g_loss_.data(), g_.data(), n);
    loss_now_ = k * kernels::dot(g_loss_.data(), shapes_[0].data(), n);
    loss_before_ = k * kernels::dot(g_loss_.data(), shapes_[1].data(), n);
}

void BridgeEnd::reform(VibratingString& string) {
    form_loads();
    for (std::size_t i = 0; i < shapes_.size(); ++i) string.gestures().reshape_driven(first_gesture_ + i, shapes_[i]);
    retake(string.modes());
}

void BridgeEnd::keep(const ModalState& modes) {
    const double* rows[2] = {g_.data(), g_loss_.data()};
    double now[2] = {0.0, 0.0};
    kernels::dot_rows(rows, lossy_ ? 2 : 1, modes.q().data(), g_.size(), now);  // one pass for both
    x_[0] = x_[1];
    x_[1] = x_[2];
    x_[2] = now[0];
    if (!lossy_) return;
    y_[0] = y_[1];
    y_[1] = y_[2];
    y_[2] = now[1];
}

void BridgeEnd::retake(const ModalState& modes) {
    const std::size_t n = g_.size();
    kernels::dot_current_previous(g_.data(), modes.q().data(), modes.d().data(), n, x_[2], x_[1]);
    if (lossy_) kernels::dot_current_previous(g_loss_.data(), modes.q().data(), modes.d().data(), n, y_[2], y_[1]);
}

double BridgeEnd::pull(const VibratingString& string, double w_now, double w_before) const {
    double free = forecast_.g;
    if (!forecast_holds(string)) {
        const double* row = g_.data();
        string.modes().predict_at(&row, 1, &free);
    }
    const double load = load_now_ * w_now - load_before_ * w_before;
    return -mu_ * (free + load - 2.0 * x_[2] + x_[1]) / (dt_ * dt_);
}

void BridgeEnd::step(VibratingString& string, double w_now, double w_before) {
    drive(string.gestures(), w_now, w_before);
    if (!string.driven_only()) {
        string.step();
        keep(string.modes());
        return;
    }
    // q'^{n+1} = free q'^{n+1} + the load's impulse, so g . q'^{n+1} needs no pass of its own.
    const double* rows[2] = {g_.data(), g_loss_.data()};
    const std::size_t m = lossy_ ? 2 : 1;
    double free[2] = {forecast_.g, forecast_.loss};
    if (!forecast_holds(string)) string.modes().predict_at(rows, m, free);
    double next[2] = {0.0, 0.0};
    string.step_driven(rows, m, next);
    x_[0] = x_[1];
    x_[1] = x_[2];
    x_[2] = free[0] + load_now_ * w_now - load_before_ * w_before;
    if (lossy_) {
        y_[0] = y_[1];
        y_[1] = y_[2];
        y_[2] = free[1] + loss_now_ * w_now - loss_before_ * w_before;
    }
    forecast_ = {next[0], next[1], string.step_index(), string.revision()};
}

void BridgeEnd::correct_damping(double w_step2) {
    // sum_j (1 - e_j) [(s_j - g_j D)^2 - s_j^2], s_j = q'^{n+1}_j - q'^{n-1}_j, D = w^{n+1} - w^{n-1}.
    if (!lossy_) return;
    damping_ += plan_->modal_loss_scale() * (w_step2 * w_step2 * loss_norm_ - 2.0 * w_step2 * (y_[2] - y_[0]));
}

double BridgeEnd::energy(const ModalState& modes, double modal_energy, double w_next, double w_now) const {
    const std::size_t n = g_.size();
    const double step = w_next - w_now;
    for (std::size_t j = 0; j < n; ++j) {
        q_[j] = modes.q()[j] - g_[j] * w_next;
        d_[j] = modes.d()[j] - g_[j] * step;
    }
    const ModalPropagator& prop = plan_->propagator();
    const double own = plan_->modal_energy_scale() *
                       kernels::modal_energy(prop.decay().data(), prop.beta().data(), q_.data(), d_.data(), n);
    const double rate = mu_ / (dt_ * dt_);
    const double cross = rate * ((x_[2] - x_[1]) - g_norm2_ * step) * step;
    const double mass = 0.5 * rate * g_norm2_ * step * step;
    const double spring = 0.25 * stiffness_ * (w_next * w_next + w_now * w_now);
    return (own - modal_energy) + cross + mass + spring;
}

}  // namespace fretbuzz
