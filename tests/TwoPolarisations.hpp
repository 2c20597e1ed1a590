#pragma once
// Shared by the two-polarisation tests: a stepper with both polarisations, started as a run
// starts it.
#include "fretbuzz/Case.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/SecondPolarisation.hpp"
#include "fretbuzz/scheme/Stepper.hpp"

namespace fretbuzz::testing {

struct TwoPolarisations {
    explicit TwoPolarisations(const Case& c, PlanOptions options = {})
        : plan(c, 1.0 / c.run.sample_rate_hz, options),
          stepper(plan, along_polarisation(c.initial_displacement, c.polarisation.angle_deg, false),
                  along_polarisation(c.initial_velocity, c.polarisation.angle_deg, false)) {
        stepper.add_second_polarisation(along_polarisation(c.initial_displacement, c.polarisation.angle_deg, true),
                                        along_polarisation(c.initial_velocity, c.polarisation.angle_deg, true));
    }
    const SecondPolarisation& y() const { return *stepper.second_polarisation(); }
    Plan plan;
    Stepper stepper;
};

}  // namespace fretbuzz::testing
