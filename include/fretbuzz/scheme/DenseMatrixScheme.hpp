#pragma once
// A literal transcription of the paper's eq. (4) in space: u^{n+1} = D u^n - D~ u^{n-1}
// + (dt^2/mu) f^n with D = S C S^-1 and D~ = S C~ S^-1 stored as full N x N matrices, and
// the contact solved at every grid point every step. It is the baseline the fast
// Stepper is measured against (bench/) and an independent check of its results (tests/):
// it shares only the scalar contact law, not the modal machinery.
#include <cstddef>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/scheme/PenaltyContact.hpp"

namespace fretbuzz {

class DenseMatrixScheme {
public:
    DenseMatrixScheme(const Case& c, double dt);

    void step();
    long step_index() const { return n_; }
    const std::vector<double>& displacement() const { return u_; }  // u^n on the grid
    // u(x, t_n) by modal synthesis of q = S^-1 u^n.
    double displacement_at(double x) const;

private:
    std::size_t n_points_;
    double dt_, mu_, length_;
    PenaltyContact contact_;
    std::vector<double> obstacle_;
    std::vector<double> d_, d_tilde_;  // row-major N x N
    std::vector<double> u_prev_, u_, u_next_, free_;
    std::vector<double> eta_prev_;
    long n_ = 1;
};

}  // namespace fretbuzz
