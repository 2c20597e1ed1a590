#pragma once
// A prescribed force F(t) on the string (a plain force gesture) at its exact position: a point
// force at x (width 0), or a force spread evenly over [x - w/2, x + w/2], whatever the grid.
// Its load on mode j is F(t) times the pad's weight on the mode,
//     s_j = mean of phi_j over the pad = phi_j(x) sin(h_j) / h_j,   h_j = j pi w / (2 L)
// (s_j = phi_j(x) for a point). Known at step n, it needs no solve of its own:
//     q^{n+1} = C q^n - C~ q^{n-1} + (dt^2/mu) f^n s + (contact),   f^n = a F(t_n)
// (a: its signed share along this polarisation), and the step's contacts are solved with the
// free prediction shifted by its load. Its work over the step, f^n (u_s^{n+1} - u_s^{n-1}) / 2
// with u_s = s . q the pad's mean displacement, is exactly what the discrete energy gains from
// it, so H - work + dissipated stays constant to round-off.
#include <cstddef>
#include <span>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/numerics/ModalBasis.hpp"
#include "fretbuzz/numerics/TimeProfile.hpp"

namespace fretbuzz {

// s_j: the mean of phi_j over the pad [x - w/2, x + w/2] (phi_j(x) where w = 0), for every mode
// of the basis. A force F spread evenly over the pad loads mode j with F s_j, and s . q is the
// pad's mean displacement.
std::vector<double> pad_mean_shapes(const ModalBasis& basis, double x, double width);

class ForceProfile {
public:
    // along: the force's signed component along the polarisation stepped, per newton of F, in
    // the solve's orientation (along z: -direction cos(angle), down being negative).
    ForceProfile(const ForceSpec& spec, const ModalBasis& basis, double dt, double along);
    // A load driven from outside, step by step (a bridge's end on its string, BridgeEnd): modal
    // shape s as given, f^n whatever drive() last set; it may act at any time.
    ForceProfile(std::vector<double> shape, const ModalBasis& basis);

    // f^n: the load per unit of shape at step n (0 where it does not act).
    // A driven load's shape changed (same size), in place: its grid values row by row (scratch:
    // one row), as a real-time voice may call it (a transform of some sizes allocates).
    void reshape(std::span<const double> shape, const ModalBasis& basis, std::span<double> scratch);

    double at_step(long n) const { return driven_ ? drive_ : along_ * force_.at(static_cast<double>(n) * dt_); }
    void drive(double load) { drive_ = load; }
    bool driven() const { return driven_; }
    // Whether its force may be non-zero at step n or at any later step (whatever its share here).
    bool acts_from(long n) const { return static_cast<double>(n) * dt_ < quiet_from_s_; }
    std::span<const double> shape() const { return shape_; }  // s_j
    // (S s)_i: the displacement at grid point i of the modal vector s.
    double on_grid(std::size_t i) const { return on_grid_[i]; }

    // Its work over one step of load f: begin_step before the modes move (u_s^{n-1} from q^n,
    // d^n), end_step after (u_s^{n+1} from q^{n+1}).
    void begin_step(std::span<const double> q, std::span<const double> d);
    void end_step(std::span<const double> q, double load);
    double work() const { return work_; }

private:
    TimeProfile force_;
    double along_, dt_, quiet_from_s_;
    std::vector<double> shape_, on_grid_;
    bool driven_ = false;
    double drive_ = 0.0;
    double before_ = 0.0;  // u_s^{n-1} of the step being taken
    double work_ = 0.0;
};

}  // namespace fretbuzz
