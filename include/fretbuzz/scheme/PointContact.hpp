#pragma once
// Contact at point obstacles held at their exact positions x_p (not at grid points): each
// point's row is phi_j(x_p), and K acts on it over a width c_p of string. The scheme's
// discrete-gradient force keeps its form at every point,
//     f_p = (Psi(eta_p^{n+1}) - Psi(eta_p^{n-1})) / (eta_p^{n+1} - eta_p^{n-1}),
//     q^{n+1} = C q^n - C~ q^{n-1} + (dt^2/mu) sum_p c_p f_p phi(x_p),
// so the energy balance stays exact, with sum_p c_p Psi(eta_p) as the contact energy. Off the
// grid, a force at one point moves the others in the same step (phi(x_p) . phi(x_q) != 0 for
// p != q): with r_p = eta_p^{n+1} - eta_p^{n-1}, a_p = eta_p^{n-1} and b_p the free step's r_p,
//     r_p + (dt^2/mu) sum_q G_pq f_q(r_q) = b_p,   G_pq = c_q phi(x_p) . phi(x_q),
// a P x P system solved by Newton's method (Eigen's LU for its steps; up to 32 unknowns on the
// stack: stepping allocates nothing) from each point's own
// scalar root. A single point, or points that do not couple (on the grid), take the law's
// scalar solve with the step factor scaled by G_pp. Every solve is a template on the contact
// law (ContactForceLaw), instantiated for the laws the plan offers (PenaltyContact).
//
// Beside obstacle points on the grid (a fretboard's board under its exact frets), a grid point's
// force f_i moves every point p by k dx M_pi f_i (M_pi = phi(x_p) . S_i), and each point's force
// moves grid point i by k c_p M_pi f_p. The grid's equations stay one scalar each given the
// points' forces,
//     r_i + k f_i(r_i) = b_i - k sum_p c_p M_pi f_p,
// so Newton's method runs on the points' P unknowns alone, each grid equation solved inside it
// (the grid's unknowns eliminated: a Schur complement, P x P, whatever the grid points in contact).
// Pads (below) join that system, one more unknown each: pad a moves grid point i by k m^a_i F_a,
// m^a_i = s_a . S_i, and grid point i moves it by k dx m^a_i f_i.
#include <cstddef>
#include <span>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/numerics/ModalBasis.hpp"
#include "fretbuzz/scheme/ContactForceLaw.hpp"

namespace fretbuzz {

// Something pressing on the string's pad-mean displacement u_s = s . q (a plucker at its exact
// position, s its pad's mean of each mode shape), solved with the points in one system: its
// force F on the string (N, solve orientation, loading the modes with (dt^2/mu) F s) at
// u_s^{n+1} = x, and dF/dx (<= 0).
class PadPress {
public:
    virtual void force_and_slope(double x, double& force, double& slope) const = 0;

protected:
    PadPress() = default;
    PadPress(const PadPress&) = default;
    PadPress& operator=(const PadPress&) = default;
    ~PadPress() = default;
};

// Parts on grid points with a solve of their own (fingers, a lumped mass each over a pad of grid
// points), solved with the points beside the grid's obstacle points: a point's force f_p raises
// pad point i's prediction by k c_p M_pi f_p, and pad point i's force F_i moves point p by
// k dx M_pi F_i. Each finger's height step s is one more unknown of the points' Newton solve; its
// pad points' equations are one scalar each given s (solved inside every evaluation, as the
// grid's obstacle points are), and the finger's own equation G(s) = 0 is one more row.
class GridPads {
public:
    // Their grid points (every pad's, one after the other).
    virtual std::span<const std::size_t> points() const = 0;
    // How many fingers, and where finger f's points end in points().
    virtual std::size_t heights() const = 0;
    virtual std::size_t end(std::size_t f) const = 0;
    // Each finger's own solve for the pads' predictions raised by `shift` (points() order): each
    // point's force per unit length on the string (solve orientation) into `force`, each finger's
    // s into `height`, its residual (zero) into `residual`, its round-off size into `size`.
    virtual void solve(std::span<const double> shift, std::span<double> force, std::span<double> height,
                       std::span<double> residual, std::span<double> size) = 0;
    // Each finger's s carried on from its last steps (Newton's start for a held note).
    virtual void guess(std::span<double> height) const = 0;
    // The same at given heights s: each pad point's equation alone; `residual` receives each
    // finger's equation G(s) / (M/dt^2) (m).
    virtual void trial(std::span<const double> shift, std::span<const double> height, std::span<double> force,
                       std::span<double> residual, std::span<double> size) = 0;
    // The last solve's or trial's slopes: at each pad point, dF_i/dw_i (s fixed) into `response`,
    // dF_i/ds into `lift`, d residual/dw_i into `pull`; each finger's d residual/ds into `slope`.
    virtual void slopes(std::span<double> response, std::span<double> lift, std::span<double> pull,
                        std::span<double> slope) const = 0;

protected:
    GridPads() = default;
    GridPads(const GridPads&) = default;
    GridPads& operator=(const GridPads&) = default;
    ~GridPads() = default;
};

class PointContact {
public:
    PointContact() = default;
    // points: heights in the solve's coordinate (obstacle below the string).
    // grid_coupled: obstacle points on the grid are solved with these (see above): M is kept.
    PointContact(const ModalBasis& basis, std::vector<PointObstacle> points, bool grid_coupled = false);

    std::size_t size() const { return points_.size(); }
    bool empty() const { return points_.empty(); }
    const PointObstacle& point(std::size_t p) const { return points_[p]; }
    std::span<const double> row(std::size_t p) const { return rows_[p]; }
    double height(std::size_t p) const { return heights_[p]; }
    double weight(std::size_t p) const { return points_[p].weight_m; }
    // G_pq = c_q phi(x_p) . phi(x_q)
    double gram(std::size_t p, std::size_t q) const { return gram_[p * points_.size() + q]; }
    // Whether the points move one another within a step (see above).
    bool coupled() const { return coupled_; }
    // Raises every point by `offset` but none above the rest line (see Plan::set_obstacle_offset).
    void set_offset(double offset);

    // What a stepper keeps between steps: eta at levels n - 1 and n, the last forces, and the
    // Newton system's storage (made once: stepping allocates nothing).
    struct State {
        std::vector<double> eta_before, eta_prev, eta_curr, force, increment, b, quotient, slope, residual, candidate;
        int iterations = 0;
        double prediction_size = 0.0;  // the largest |height| or |predicted u| of the awake points
        bool joint = false;  // the last step solved points and grid together (Newton)
        // Points the screening put to sleep (apart from the string, and it cannot reach them
        // before the scheduler says): no force, no prediction needed, eta held a metre apart.
        std::vector<char> resting;
        std::size_t awake = 0;
        std::vector<std::size_t> awake_list;  // (Newton's scratch)
        std::vector<std::size_t> pushing;     // (the grid's solve's scratch: the points pushing)
        // With GridPads: each pad point's shift, force and slopes (one per grid point: room for any
        // pad); each finger's height step, its trial, residual, round-off size and slope.
        std::vector<double> pad_shift, pad_force, pad_response, pad_lift, pad_pull;
        std::vector<double> height, height_candidate, height_residual, height_size, height_slope;
        std::vector<std::size_t> height_end;  // where each finger's pad points end
        // With Pads: each pad's unknown x, its force F(x), dF/dx, residual and trial x, and the
        // x and force of a solve beside the grid (room for the pads planned: make_state).
        std::vector<double> press_x, press_force, press_slope, press_residual, press_trial;
        std::vector<double> press_moved, press_own;
    };
    // pads: how many Pads a solve may take (the plan's pluckers), fixed here: no capacity of the
    // solve changes which contacts it takes.
    State make_state(std::size_t pads = 0) const;
    // eta at levels n (u_now = phi . q^n) and n - 1 (phi . (q^n - d^n)); every point awake.
    void start(State& s, std::span<const double> q, std::span<const double> d) const;
    void rest(State& s, std::size_t p) const;
    // Point p awake again, eta from the state (q^n, d^n).
    void wake(State& s, std::size_t p, std::span<const double> q, std::span<const double> d) const;
    // Pads pressing on their u_s in the same step (pluckers at their exact positions): with pad
    // a's force F_a(x_a) the system gains one unknown per pad,
    //     r_p + k sum_q G_pq f_q + k sum_a h^a_p F_a(x_a) = b_p,
    //     x_a - w_a - k sum_q c_q h^a_q f_q - k sum_b (s_a . s_b) F_b(x_b) = 0,
    // h^a_p = phi(x_p) . s_a, w_a the free step's u_s; x_a holds the pad's solution alone on entry
    // and the joint one on return. Two pads always move one another (their shapes overlap in
    // mode space), so where either presses they are solved together.
    struct Pad {
        const PadPress* press = nullptr;
        double predicted = 0.0;            // w
        double self = 0.0;                 // s . s
        std::span<const double> cross;     // s . s_b for every pad b of the solve (none needed for one pad)
        std::span<const double> coupling;  // h_p
        double x = 0.0;
        std::span<const double> grid;  // m_i = s . S_i at every grid point (with a Grid only)
    };
    // One step: `predicted[p]` is u at point p after a free step; k = dt^2/mu. Fills s.force
    // (force per unit length f_p), moves eta one level on, and returns whether any point pushed.
    // pads: at most the State's room (make_state).
    template <ContactForceLaw Law>
    bool solve(State& s, std::span<const double> predicted, const Law& law, double k, std::span<Pad> pads = {}) const;
    // The grid's active obstacle points in the same step (grid_coupled() only): each one's
    // eta^{n-1} (a) and free-step increment (b); `solutions` receives each one's solution with
    // the points' forces (the caller moves the grid's eta on).
    struct Grid {
        std::span<const std::size_t> points;
        std::span<const double> a, b;
        std::span<ContactSolution> solutions;
        double step = 0.0;  // dx
        GridPads* pads = nullptr;  // fingers' pads, solved with them (their grid points are not in `points`)
    };
    // The points, the pads and the grid's active obstacle points in one solve (no point need be
    // grid_coupled() where there are none awake).
    template <ContactForceLaw Law>
    bool solve(State& s, std::span<const double> predicted, const Law& law, double k, Grid& grid,
               std::span<Pad> pads = {}) const;
    bool grid_coupled() const { return grid_points_ != 0; }
    // M_pi = phi(x_p) . S_i
    double grid_coupling(std::size_t p, std::size_t i) const { return grid_rows_[p * grid_points_ + i]; }
    // sum_p c_p Psi(eta_p) at the current and the previous level.
    template <ContactForceLaw Law>
    double potential(const State& s, const Law& law, bool current) const;
    // Adds the modal impulse k sum_p c_p f_p phi(x_p) to `impulse`.
    void add_impulse(const State& s, double k, std::span<double> impulse) const;

private:
    // The points' own solve (alone, then together where they couple), eta not yet moved on.
    // held: Newton's start only (a joint solve follows), eta carried on where in contact.
    template <ContactForceLaw Law>
    void solve_points(State& s, std::span<const double> predicted, const Law& law, double k, std::span<Pad> pads,
                      bool held = false) const;
    bool commit(State& s) const;  // moves eta one level on; whether any point pushed
    // (Newton's method on the points' system is PointNewton's, on the points beside the grid
    // GridNewton's: private headers of src/scheme.)

    std::vector<PointObstacle> points_;
    std::vector<double> planned_heights_, heights_;
    std::vector<std::vector<double>> rows_;
    std::vector<double> gram_;  // G_pq = c_q phi(x_p) . phi(x_q), row by row
    bool coupled_ = false;
    std::size_t grid_points_ = 0;
    std::vector<double> grid_rows_;  // M_pi, point by point (empty unless grid_coupled)
};

}  // namespace fretbuzz
