#pragma once
// Decides, with a proof rather than a guess, when each grid point must next be looked at,
// so that the contact solve runs only where contact is possible. The scheme's results are
// unchanged: a point left out is one where the exact answer is "no force".
//
// While no contact force acts, every mode moves freely, and the string's speed is bounded
// at every point by W = sqrt(2/L) sum_j omega_j R_j (R_j: amplitude of mode j's exact free
// motion, |dq_j/dt| <= omega_j R_j). A point found at height gap above the obstacle cannot
// reach it before the string has "travelled" gap, i.e. before the reach budget
// Phi(t) = integral of W dt has grown by gap since the check. Each sleeping point waits in a
// priority queue keyed by the budget at which it must wake; W is recomputed after every
// contact impulse (the motion changed) and from time to time as the modes decay. Point
// positions do not jump at an impulse (S delta is local to the forced points), so the
// budget carries over.
//
// The budget grows for ever, while the motion does not: |u(x_i, t)| <= E_i = sum_j |S_ij| R_j
// for as long as the motion stays free (R_j bounds |q_j| over the whole free motion). A point
// whose obstacle lies deeper than E_i cannot touch before the next impulse, however long the
// flight: it is parked, out of the queue, and goes back to it at the next impulse, keyed by
// the gap it is known to keep (u_i >= -E_i). A string ringing above its frets after the
// last contact thus stops paying for checks of points it can no longer reach.
#include <cstddef>
#include <functional>
#include <queue>
#include <span>
#include <utility>
#include <vector>

#include "fretbuzz/numerics/CacheAligned.hpp"

#include "fretbuzz/scheme/Plan.hpp"

namespace fretbuzz {

class ContactScheduler {
public:
    explicit ContactScheduler(const Plan& plan);

    // Recomputes the speed bound from the free motion of the state (q^n, d^n).
    void update_speed(std::span<const double> q, std::span<const double> d);
    // The motion changed (an impulse, or decay to account for): with points asleep the bound
    // is recomputed now; with none it only matters once a point goes to sleep, so it waits
    // for refresh(). A string resting on a point obstacle then never pays for it.
    void motion_changed(std::span<const double> q, std::span<const double> d);
    void refresh(std::span<const double> q, std::span<const double> d) {
        if (stale_) update_speed(q, d);
    }
    // A contact step changed the motion by the impulse iota = scale sum_i f_i S_i (S_i: row i of
    // S), added to q and d. R_j is a seminorm of (q_j, d_j), so it grows by at most
    // |iota_j| R_j(1, 1) <= |scale| sum_i |f_i| |S_ij| R_j(1, 1): each bound grows by
    // |scale f_i| times a weight of point i (one pass over its row, once), and is recomputed in
    // full once the speed bound has grown by a quarter (a loose bound wakes points early).
    void pushed(std::span<const double> q, std::span<const double> d,
                std::span<const std::pair<std::size_t, double>> forces, double scale);
    // The same with the impulse iota itself (many points, projected onto the modes in one go):
    // the bounds grow by sum_j |iota_j| R_j(1, 1) (times omega_j for the speed), one pass and no
    // point's weight, and tighter than the sum over points; recomputed in full once the speed
    // bound is 5 % above the last full one (such pushes come step after step).
    void pushed(std::span<const double> q, std::span<const double> d, std::span<const double> impulse);
    // As refresh, and also brings the per-mode amplitudes up to date (a change of head needs them).
    void refresh_amplitudes(std::span<const double> q, std::span<const double> d) {
        if (stale_ || amplitudes_behind_) update_speed(q, d);
    }
    double speed() const { return speed_; }
    // A cheap look at a point uses only the first head_modes() modes: the others move it by
    // at most tail_bound() (sqrt(2/L) times the sum of their free amplitudes).
    std::size_t head_modes() const { return head_; }
    void set_head_modes(std::size_t head);
    double tail_bound() const { return tail_; }
    // Appends to `out` the sleeping points that might touch by the end of the coming step.
    void pop_due(std::vector<std::size_t>& out);
    // Puts point i to sleep given its current gap u - g; false if it is too close to sleep.
    bool sleep(std::size_t i, double gap);
    // Parks point i if the free motion's envelope cannot reach its obstacle; false if it can,
    // or if the amplitudes are not those of the current free motion. A point is tested once
    // per set of amplitudes (one pass over its row).
    bool park(std::size_t i);
    // Parks every sleeping point due within the next `steps` steps that can be parked; true if
    // no sleeping point is then due in that time (the others keep their places).
    bool park_due(long steps);
    long parks() const { return parks_; }        // points parked so far
    long releases() const { return releases_; }  // times parked points went back to the queue
    // Makes point i due at once (it will be popped by the next pop_due).
    void wake_now(std::size_t i) { queue_.emplace(budget_, i); }
    // No point is asleep (the speed bound is then not needed until one goes to sleep).
    bool idle() const { return queue_.empty(); }
    // Forgets every sleeping point (the state changed from outside: all must be looked at again,
    // and the damping may have changed).
    void clear();
    // Spends one step of budget (call once per step, before any update_speed for the new state).
    void end_step() { end_steps(1); }
    void end_steps(long steps);
    // True if no sleeping point can touch during the next `steps` steps.
    bool quiet_for(long steps) const;

private:
    using Entry = std::pair<double, std::size_t>;  // (budget at which to wake, point)

    const Plan& plan_;
    double norm_;            // sqrt(2/L) >= |phi_j(x)|
    double speed_ = 0.0;     // W
    double slack_ = 0.0;     // absolute allowance for round-off in u
    double budget_ = 0.0;    // Phi(t_n)
    bool stale_ = false;     // speed_ predates the last change of motion (no point asleep)
    std::size_t head_;
    double tail_ = 0.0;
    AlignedVector amplitude_;  // R_j at the last update_speed
    // R_j(1, 1), and omega_j R_j(1, 1): how much a unit impulse on mode j can add to the bounds.
    AlignedVector push_reach_, push_speed_;
    // Per grid point, sum_j |S_ij| times those, and the reach beyond the default head modes
    // (NaN until first needed).
    struct PointWeight {
        double speed, reach, tail;
    };
    std::vector<PointWeight> point_weight_;
    double full_speed_ = 0.0;          // speed_ at the last update_speed
    bool amplitudes_behind_ = false;   // impulses since then are in the bounds, not in amplitude_
    void compute_push_weights();
    const PointWeight& point_weight(std::size_t i);
    // Common start of both pushed: parked points released; false (the bound marked stale) if
    // no point is asleep, so that the bound is not needed until one is.
    bool bound_needed_after_push();
    // Common end of both pushed: the growths of the bounds (before the slack) added.
    void grow_bounds(double speed, double reach, double tail, std::span<const double> q, std::span<const double> d,
                     double looseness);
    std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue_;
    // Parking: the points and their envelope E_i, the amplitudes the parked points were tested
    // with (elementwise smallest: later amplitudes must stay within them), and which amplitudes
    // each point was last tested with (a point that failed is not tested again with the same ones).
    std::vector<std::size_t> parked_;
    AlignedVector envelope_;
    std::vector<Entry> held_;  // points park_due could not park
    std::vector<double> park_amplitude_;
    std::vector<long> tested_with_;
    std::vector<double> row_scratch_;  // a row tested for parking, not kept by the basis
    std::vector<double> retry_reach_;  // test a point that failed again once sum_j R_j is below this
    double reach_ = 0.0;               // sum_j R_j at the last update_speed
    long amplitude_epoch_ = 0;
    long park_epoch_ = -1;  // the amplitudes last folded into park_amplitude_
    long parks_ = 0, releases_ = 0;
    void unpark();
    void check_parked();
};

}  // namespace fretbuzz
