#pragma once
// Watches the energy balance over the samples a run reports, for the run summary.
#include <algorithm>
#include <cmath>

#include "fretbuzz/run/RunObserver.hpp"

namespace fretbuzz {

class EnergyAudit {
public:
    // work: done on the string by external forces (the fingers' pressing forces) so far.
    void record(double h, double dissipated, RunSummary& s, double work = 0.0) {
        if (!started_) {
            started_ = true;
            s.energy_initial_j = h;
            previous_ = h;
        }
        largest_work_ = std::max(largest_work_, std::abs(work));
        const double scale = std::max(s.energy_initial_j, largest_work_);  // initial or injected energy
        const double reference = scale > 0.0 ? scale : 1.0;
        s.max_relative_energy_increase = std::max(s.max_relative_energy_increase, (h - previous_) / reference);
        // Relative to the largest energy of the run so far: a run that starts at rest and is
        // driven (H0 = 0) is not judged against the tiny work of its first steps.
        largest_error_ = std::max(largest_error_, std::abs(h - work + dissipated - s.energy_initial_j));
        s.max_relative_balance_error = largest_error_ / reference;
        previous_ = h;
        s.energy_final_j = h;
        s.dissipated_j = dissipated;
    }

private:
    bool started_ = false;
    double previous_ = 0.0;
    double largest_work_ = 0.0;
    double largest_error_ = 0.0;
};

}  // namespace fretbuzz
