#pragma once
// A string's free-flight scheduler (PlanOptions::screen_contacts): the ContactScheduler's proof
// of when each sleeping point (grid points i < N, exact points as N + p) may next touch, the
// points it says are due looked at again, and the flight of the head modes over the steps where
// none can touch (the string then lands the other modes in one jump: FreeFlight).
#include <cstddef>
#include <span>
#include <vector>

#include "fretbuzz/scheme/ContactScheduler.hpp"
#include "fretbuzz/scheme/ExactPoints.hpp"
#include "fretbuzz/scheme/GridContact.hpp"
#include "fretbuzz/scheme/ModalState.hpp"
#include "fretbuzz/scheme/Plan.hpp"

namespace fretbuzz {

class Screening {
public:
    explicit Screening(const Plan& plan);

    bool on() const { return on_; }
    ContactScheduler& scheduler() { return scheduler_; }
    const ContactScheduler& scheduler() const { return scheduler_; }
    ContactScheduler* if_on() { return on_ ? &scheduler_ : nullptr; }

    // The speed bound from the state at step n (the first step, a restart, a flight's end when due).
    void start(const ModalState& modes, long n);
    void set_next_refresh(long step) { next_speed_refresh_ = step; }
    // After a step into step `next`: whether the free modes' decay is due to tighten the bound
    // (then done, with the motion as it is).
    bool refresh_after_step(const ModalState& modes, long next);
    // After a flight that ended at step n.
    void refresh_after_flight(const ModalState& modes, long n);

    // The sleeping points due in the coming step looked at: back to their solves, or asleep again.
    // field: scratch of the grid's size (u^n by one transform where many are due).
    void wake_due(const ModalState& modes, GridContact& grid, ExactPoints& points, std::span<double> field) {
        if (!on_) return;
        due_.clear();
        scheduler_.pop_due(due_);
        if (!due_.empty()) wake(modes, grid, points, field);
    }
    // Flies the first `head` modes over up to `steps` steps while no sleeping point can touch,
    // sampling the probes' rows into u (and v: velocities, if not null) at every step; stops at
    // a point that might touch (made due at once). Returns the steps flown.
    long fly_head(ModalState& modes, long steps, std::size_t head, std::span<const std::vector<double>> probes,
                  std::vector<double>& u, std::vector<double>* v);

private:
    // u_i >= (first `head` modes of u_i) - tail: a lower bound on the gap, cheap to get.
    bool sleeps_on_low_modes(std::size_t i, std::size_t head, double tail, const ModalState& modes);
    void wake(const ModalState& modes, GridContact& grid, ExactPoints& points, std::span<double> field);  // due_

    const Plan* plan_;
    ContactScheduler scheduler_;
    bool on_;
    long next_speed_refresh_ = 0;
    std::vector<std::size_t> due_;  // scratch: sleeping points to check now
};

}  // namespace fretbuzz
