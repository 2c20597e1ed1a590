#pragma once
// Rules out, with a proof rather than a guess, the grid points that cannot touch the
// obstacle during the next window of M steps, so the contact solve and the evaluation of
// u run only where contact is possible. The scheme's results are unchanged: a skipped
// point is one where the exact answer is "no force".
//
// Over a window starting at step n0 from (q^{n0}, d^{n0}), each mode moves freely by at most
// dev_j = R_j min(2, omega_j M dt) (R_j: the amplitude of its exact free motion), so
// |u_i - u_i^{n0}| <= V = sqrt(2/L) sum_j dev_j at every point. A contact impulse delta
// added during the window widens V by sqrt(2/L) sum_j kappa_j |delta_j|, kappa_j bounding
// the free response to an impulse (ModalPropagator::impulse_gain). A point is a candidate
// when u_i^{n0} - g_i <= V; points sorted by that distance make the candidates a prefix
// that grows when V does. The window length adapts to keep its fixed cost (one sine
// transform and a sort) balanced against the per-step work on candidates.
#include <cstddef>
#include <span>
#include <vector>

#include "fretbuzz/scheme/Plan.hpp"

namespace fretbuzz {

class ContactScreen {
public:
    explicit ContactScreen(const Plan& plan);

    // Starts a window at step n0. u is S q^{n0} on the grid; always_include lists points
    // that must be solved whatever their distance (recent contacts).
    void begin(long n0, std::span<const double> q, std::span<const double> d, std::span<const double> u,
               std::span<const std::size_t> always_include);
    bool window_over(long n) const { return n >= window_end_; }
    // Widens the bound by the effect of an impulse added to q^{n+1}; returns how many
    // points joined the candidates (they are at the end of candidates()).
    std::size_t widen(std::span<const double> impulse);
    // Candidate points for the current window.
    std::span<const std::size_t> candidates() const { return candidates_; }
    long window_length() const { return length_; }
    // Adapts the next window's length from the work this one required.
    void finish_window(double mean_candidates);

private:
    std::size_t extend_prefix();

    const Plan& plan_;
    double norm_;  // sqrt(2/L), the largest |phi_j(x)|
    long length_ = 32;
    long window_end_ = 0;
    double bound_ = 0.0;
    bool unbounded_ = false;
    std::vector<double> gain_;              // kappa_j for the current window
    std::vector<double> distance_;          // u_i^{n0} - g_i
    std::vector<std::size_t> order_;        // obstacle points by increasing distance
    std::size_t prefix_ = 0;                // order_[0..prefix_) are candidates
    std::vector<std::size_t> candidates_;
    std::vector<unsigned char> is_candidate_;
};

}  // namespace fretbuzz
