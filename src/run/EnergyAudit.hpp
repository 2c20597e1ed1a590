#pragma once
// Watches the energy balance over the samples a run reports, for the run summary.
#include <algorithm>
#include <cmath>

#include "fretbuzz/run/RunObserver.hpp"

namespace fretbuzz {

class EnergyAudit {
public:
    void record(double h, double dissipated, RunSummary& s) {
        if (!started_) {
            started_ = true;
            s.energy_initial_j = h;
            previous_ = h;
        }
        const double reference = s.energy_initial_j > 0.0 ? s.energy_initial_j : 1.0;
        s.max_relative_energy_increase = std::max(s.max_relative_energy_increase, (h - previous_) / reference);
        s.max_relative_balance_error =
            std::max(s.max_relative_balance_error, std::abs(h + dissipated - s.energy_initial_j) / reference);
        previous_ = h;
        s.energy_final_j = h;
        s.dissipated_j = dissipated;
    }

private:
    bool started_ = false;
    double previous_ = 0.0;
};

}  // namespace fretbuzz
