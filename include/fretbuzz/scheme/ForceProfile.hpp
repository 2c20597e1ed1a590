#pragma once
// A prescribed force F(t) on the string (a plain force gesture), spread evenly over a pad of
// grid points (the nearest point when the pad is narrower than the grid step). Direction
// +1 pushes toward the fretboard (down in the solve's orientation), -1 pulls away from it.
// Known at step n, its force density f_i = -direction F(t_n) / (n_pad dx) enters the scheme
// explicitly, u_i^{n+1} = w_i + (dt^2/mu) (f_i + obstacle force at i), the obstacle at a pad
// point being solved with it (its scalar equation with w_i shifted by (dt^2/mu) f_i). Its
// work over the step, dx sum_i f_i (u_i^{n+1} - u_i^{n-1}) / 2, is exactly what the discrete
// energy gains from it, so H - work + dissipated stays constant to round-off.
#include <cstddef>
#include <span>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/scheme/PenaltyContact.hpp"
#include "fretbuzz/scheme/PlayedPart.hpp"
#include "fretbuzz/scheme/TimeProfile.hpp"

namespace fretbuzz {

class ForceProfile final : public PlayedPart {
public:
    // obstacle: heights at every grid point in the solve's orientation (-inf: none); k = dt^2/mu.
    ForceProfile(const ForceSpec& spec, double dx, const std::vector<double>& obstacle, const PenaltyContact& law,
                 double dt, double k);

    const std::vector<std::size_t>& pad() const override { return pad_; }
    void start(std::span<const double> u0, std::span<const double> u1) override;
    // Step n -> n + 1 from the pad points' free predictions w; writes the total force per
    // unit length at each pad point and returns sum_i Psi_obstacle(eta_i^{n+1}) over the pad.
    double step(long n, std::span<const double> predicted, std::span<double> force) override;
    std::span<const double> current() const override { return u_curr_; }
    std::span<const double> previous() const override { return u_prev_; }
    void read_obstacle(const std::vector<double>& obstacle) override;
    double work() const override { return work_; }
    double body_height() const override;  // NaN: a force has no body
    int max_iterations() const override { return max_iterations_; }
    // In the last step: whether the obstacle pushed on a pad point, and whether the force acted.
    bool touched_obstacle() const override { return touched_obstacle_; }
    bool acted() const override { return acted_; }

private:
    TimeProfile force_;
    double direction_, dx_, dt_, k_;
    const PenaltyContact& law_;
    std::vector<std::size_t> pad_;
    std::vector<double> g_, u_curr_, u_prev_;
    double work_ = 0.0;
    int max_iterations_ = 0;
    bool touched_obstacle_ = false, acted_ = false;
};

}  // namespace fretbuzz
