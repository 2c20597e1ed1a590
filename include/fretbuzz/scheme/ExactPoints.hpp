#pragma once
// A string's point obstacles at their exact positions (Plan::point_contact) as it steps: their
// solve's state (eta, forces, Newton's storage), the free prediction at each point, and the next
// step's prediction where this step's pass formed it.
#include <cstddef>
#include <span>
#include <vector>

#include "fretbuzz/scheme/ContactScheduler.hpp"
#include "fretbuzz/scheme/ForceGestures.hpp"
#include "fretbuzz/scheme/ModalState.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/StepRecord.hpp"

namespace fretbuzz {

class ExactPoints {
public:
    explicit ExactPoints(const Plan& plan);

    const PointContact& contact() const { return *contact_; }
    PointContact::State& state() { return state_; }
    const PointContact::State& state() const { return state_; }
    std::size_t awake() const { return state_.awake; }
    // Whether a point pushed in the step being taken.
    bool pushed() const { return pushed_; }
    void set_pushed(bool pushed) { pushed_ = pushed; }

    // Every point awake, eta from the state (the first step, a restart).
    void start(const ModalState& modes) { contact_->start(state_, modes.q(), modes.d()); }
    // Point p awake again (the screening found it may touch).
    void wake(std::size_t p, const ModalState& modes);
    // The points apart from the string over both levels that the screening lets sleep (refresh:
    // its speed bound brought up to date first, as after a step; a restart has just made it).
    void put_to_sleep(ContactScheduler& scheduler, const ModalState& modes, bool refresh);

    // The awake points and their rows, in order, into room for kernels::kMaxPassRows; how many.
    std::size_t awake_rows(std::size_t* which, const double** rows) const;
    // The free step's u at each awake point, shifted by the step's loads (gestures: null if none).
    void predict(const ModalState& modes, long n, std::span<double> scratch, const ForceGestures* loads);
    std::span<double> predicted() { return predicted_; }
    // The pass into step `step` formed the prediction at awake point which[r]: values[r].
    void keep_forecast(const std::size_t* which, const double* values, std::size_t count, long step) {
        for (std::size_t r = 0; r < count; ++r) forecast_[which[r]] = values[r];
        forecast_step_ = step;
    }
    void forget_forecast() { forecast_step_ = -1; }

    // sum_p c_p (Psi(eta_p^n) + Psi(eta_p^{n-1})) / 2.
    template <class Law>
    double energy(const Law& law) const {
        if (state_.awake == 0) return 0.0;  // (no points, or all resting: apart, Psi = 0)
        return 0.5 * (contact_->potential(state_, law, true) + contact_->potential(state_, law, false));
    }
    // Their impulse k sum_p c_p f_p phi(x_p) added to `impulse`.
    void add_impulse(double k, std::span<double> impulse) const { contact_->add_impulse(state_, k, impulse); }
    // The points' forces as N at their positions: report(x, force) for each that pushed.
    template <class Report>
    void each_force(Report&& report) const {
        for (std::size_t p = 0; p < contact_->size(); ++p)
            if (state_.force[p] != 0.0) report(contact_->point(p).x_m, state_.force[p] * contact_->weight(p));
    }

private:
    const PointContact* contact_;
    PointContact::State state_;
    std::vector<double> predicted_;  // u at each point after a free step
    std::vector<double> forecast_;   // the free prediction at each point, formed by the last step's pass
    long forecast_step_ = -1;        // the step it belongs to
    bool pushed_ = false;
};

}  // namespace fretbuzz
