#pragma once
// A Case is a complete, resolved description of one simulation: the string, its
// modes, the obstacle sampled on the grid, the initial state, the contact law,
// and what to compute and record. Case files (TOML) and the built-in cases are
// turned into a Case; the scheme only ever sees a Case.
#include <optional>
#include <string>
#include <vector>

#include "fretbuzz/model/ModeTable.hpp"

namespace fretbuzz {

struct StringProperties {
    double length_m = 0.0;          // L, nut at x = 0, bridge at x = L
    double tension_n = 0.0;         // T
    double linear_density = 0.0;    // mu, kg/m
};

// Penalty contact law f(eta) = K [eta]_+^alpha, eta = g - u (penetration).
struct ContactLaw {
    double stiffness = 1e13;  // K
    double exponent = 1.5;    // alpha >= 1
};

struct RunSettings {
    double sample_rate_hz = 0.0;              // Fe
    double duration_s = 0.0;
    std::optional<double> output_rate_hz;     // empty: one output row per time step ("native")
    double audio_rate_hz = 48000.0;
    // Run even where modes alias onto low frequencies under contact (see SamplingCheck).
    bool allow_aliasing = false;
};

struct Case {
    std::string name;
    std::string description;
    StringProperties string;
    ModeTable modes;
    // Obstacle height g(x_i) at the interior grid points x_i = i L / (Nm + 1), i = 1..Nm.
    // -infinity where nothing can be touched.
    std::vector<double> obstacle_height_m;
    // The obstacle lies above the string: contact where u > g, the force pushes down.
    // The scheme runs the mirror image (u -> -u) and mirrors its outputs back.
    bool obstacle_above = false;
    // Initial modal displacement q_j(0) and velocity dq_j/dt(0), j = 1..Nm.
    std::vector<double> initial_displacement;
    std::vector<double> initial_velocity;
    ContactLaw contact;
    RunSettings run;
    std::vector<double> observation_points_m;
    // The case file text this Case was built from (kept in the outputs).
    std::string source_text;
    // What reading the case found doubtful but allowed (shown to the user, kept in summary.json).
    std::vector<std::string> warnings;

    std::size_t mode_count() const { return modes.size(); }
    double grid_step() const { return string.length_m / static_cast<double>(mode_count() + 1); }
    double grid_point(std::size_t i) const { return static_cast<double>(i + 1) * grid_step(); }
    // +1, or -1 when the obstacle is above: multiplies u to get the coordinate in which
    // the contact solve sees an obstacle below.
    double contact_orientation() const { return obstacle_above ? -1.0 : 1.0; }
    // Whether any grid point has an obstacle to touch.
    bool has_obstacle() const;

    // Removes all losses (sigma_j = 0), for energy-conservation studies.
    void make_lossless();
    // Checks every field; throws InputError naming the first bad one.
    void validate() const;

    // Limits of validate() on derived quantities: the decay of a mode within one step,
    // the phase of its one-step map, and the contact law's exponent (the penalty solve is
    // tested for alpha in [1, 3]; far above, K [g - u]^alpha under- and overflows).
    static constexpr double kMaxSigmaDt = 100.0;
    static constexpr double kMaxOmegaDt = 1e6;
    static constexpr double kMaxExponent = 10.0;
};

}  // namespace fretbuzz
