#pragma once
// Watches the energy balance over the samples a run reports, for the run summary. The scheme
// keeps H - W + D = H^{1/2} (H the energy, W the work external forces have done on the
// string, D the energy dissipated so far), so H - W never rises but by round-off. Both
// figures are relative to the larger of the initial energy H^{1/2} and the largest |W| so
// far: a run that starts at rest and is played (H^{1/2} = 0) is judged against the work put
// in, not against the work of its first step.
#include <algorithm>
#include <cmath>

#include "fretbuzz/run/RunObserver.hpp"

namespace fretbuzz {

class EnergyAudit {
public:
    // work: done on the string by external forces (pressing fingers, force gestures, pluckers) so far.
    void record(double h, double dissipated, double work = 0.0) {
        if (!started_) {
            started_ = true;
            initial_ = h;
            previous_ = h - work;
        }
        largest_work_ = std::max(largest_work_, std::abs(work));
        const double scale = std::max(initial_, largest_work_);  // initial or injected energy
        reference_ = scale > 0.0 ? scale : 1.0;
        largest_rise_ = std::max(largest_rise_, h - work - previous_);
        balance_ = (h - work + dissipated - initial_) / reference_;
        largest_error_ = std::max(largest_error_, std::abs(h - work + dissipated - initial_));
        previous_ = h - work;
        final_ = h;
        dissipated_ = dissipated;
    }

    // (H - W + D - H^{1/2}) at the last sample, relative as above: what a row of the balance shows.
    double relative_balance() const { return balance_; }
    // The largest rise of H - W between samples, and the largest |H - W + D - H^{1/2}|, relative.
    double max_relative_energy_increase() const { return largest_rise_ / reference_; }
    double max_relative_balance_error() const { return largest_error_ / reference_; }

    // The figures a one-string run's summary gives of its balance.
    void write_to(RunSummary& s) const {
        s.energy_initial_j = initial_;
        s.energy_final_j = final_;
        s.dissipated_j = dissipated_;
        s.max_relative_energy_increase = max_relative_energy_increase();
        s.max_relative_balance_error = max_relative_balance_error();
    }

private:
    bool started_ = false;
    double initial_ = 0.0, final_ = 0.0, dissipated_ = 0.0;
    double reference_ = 1.0;
    double balance_ = 0.0;
    double previous_ = 0.0;  // H - W at the last sample
    double largest_work_ = 0.0;
    double largest_rise_ = 0.0;
    double largest_error_ = 0.0;
};

}  // namespace fretbuzz
