#include "fretbuzz/reference/StringProblem.hpp"

#include <cmath>
#include <numbers>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/numerics/ModalBasis.hpp"

namespace fretbuzz::reference {

double StringProblem::wave_speed() const { return std::sqrt(tension_n / linear_density); }

void StringProblem::validate() const {
    require_positive("string length L", length_m);
    require_positive("tension T", tension_n);
    require_positive("linear density mu", linear_density);
    require_non_negative("bending stiffness EI", bending_stiffness);
    require_non_negative("loss sigma0", loss_per_s);
    require_positive("contact stiffness K", contact_stiffness);
    require_at_least("contact exponent alpha", contact_exponent, 1.0);
    if (!obstacle || !initial_shape) throw InputError("string problem: obstacle and initial shape must both be given");
}

Case to_modal_case(const StringProblem& problem, const ModalDiscretisation& d) {
    problem.validate();
    Case c;
    c.name = "string-problem";
    c.description = "modal discretisation of a reference string problem";
    c.string = {problem.length_m, problem.tension_n, problem.linear_density};
    const double c0 = problem.wave_speed();
    // Inharmonicity of the simply supported stiff string: B = pi^2 EI / (T L^2).
    const double inharmonicity =
        std::numbers::pi * std::numbers::pi * problem.bending_stiffness / (problem.tension_n * problem.length_m * problem.length_m);
    for (std::size_t j = 1; j <= d.modes; ++j) {
        const double jj = static_cast<double>(j);
        c.modes.frequency_hz.push_back(jj * c0 / (2.0 * problem.length_m) * std::sqrt(1.0 + inharmonicity * jj * jj));
        c.modes.sigma_per_s.push_back(problem.loss_per_s);
        c.modes.source.push_back(ModeSource::model);
    }
    std::vector<double> u0(d.modes);
    c.obstacle_height_m.resize(d.modes);
    for (std::size_t i = 0; i < d.modes; ++i) {
        c.obstacle_height_m[i] = problem.obstacle(c.grid_point(i));
        u0[i] = problem.initial_shape(c.grid_point(i));
    }
    // The scheme's own transform, so the grid values of u(x, 0) are reproduced exactly.
    const ModalBasis basis(problem.length_m, d.modes);
    c.initial_displacement.resize(d.modes);
    basis.to_modes(u0, c.initial_displacement);
    c.initial_velocity.assign(d.modes, 0.0);
    c.contact = {problem.contact_stiffness, problem.contact_exponent};
    c.run.sample_rate_hz = d.sample_rate_hz;
    c.run.duration_s = d.duration_s;
    c.run.output_rate_hz = d.output_rate_hz;
    c.observation_points_m = {d.observation_point_m};
    return c;
}

}  // namespace fretbuzz::reference
