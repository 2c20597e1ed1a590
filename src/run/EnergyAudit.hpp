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
    void record(double h, double dissipated, RunSummary& s, double work = 0.0) {
        if (!started_) {
            started_ = true;
            s.energy_initial_j = h;
            previous_ = h - work;
        }
        largest_work_ = std::max(largest_work_, std::abs(work));
        const double scale = std::max(s.energy_initial_j, largest_work_);  // initial or injected energy
        const double reference = scale > 0.0 ? scale : 1.0;
        largest_rise_ = std::max(largest_rise_, h - work - previous_);
        s.max_relative_energy_increase = largest_rise_ / reference;
        balance_ = (h - work + dissipated - s.energy_initial_j) / reference;
        largest_error_ = std::max(largest_error_, std::abs(h - work + dissipated - s.energy_initial_j));
        s.max_relative_balance_error = largest_error_ / reference;
        previous_ = h - work;
        s.energy_final_j = h;
        s.dissipated_j = dissipated;
    }

    // (H - W + D - H^{1/2}) at the last sample, relative as above: what a row of the balance shows.
    double relative_balance() const { return balance_; }

private:
    bool started_ = false;
    double balance_ = 0.0;
    double previous_ = 0.0;  // H - W at the last sample
    double largest_work_ = 0.0;
    double largest_rise_ = 0.0;
    double largest_error_ = 0.0;
};

}  // namespace fretbuzz
