#pragma once
// A Case is a complete, resolved description of one simulation: the string, its
// modes, the obstacle sampled on the grid, the initial state, the contact law,
// and what to compute and record. Case files (TOML) and the built-in cases are
// turned into a Case; the scheme only ever sees a Case.
#include <array>
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

// Which law acts at the obstacle: the penalty K [eta]_+^alpha, or its rigid limit, Newton's
// impact law (no penetration at the velocity level, restitution e; scheme/NewtonImpact.hpp).
enum class ContactLawKind { penalty, impact };
// "penalty" or "impact"; anything else is an InputError naming `key` and the two names.
ContactLawKind contact_law_named(const std::string& word, const std::string& key);
const char* contact_law_name(ContactLawKind law);

// Penalty contact law f(eta) = K [eta]_+^alpha, eta = g - u (penetration), or the impact law.
struct ContactLaw {
    double stiffness = 1e13;  // K
    double exponent = 1.5;    // alpha >= 1
    ContactLawKind law = ContactLawKind::penalty;
    double restitution = 0.0;  // e in [0, 1]: normal velocity after an impact = -e x before (impact law)
};

// A lumped finger (or thumb) on the far side of the string from the fretboard: a mass that
// touches the string along a pad of grid points through a penalty contact of its own, with
// a Hunt-Crossley contact loss, pushed toward the fretboard by a force that varies in time.
// See scheme/Finger.hpp for the model and its sources.
struct FingerSpec {
    std::string key = "finger";   // where it was given (for messages): "finger[0]", "fret", "--fret"
    double position_m = 0.0;      // pad centre, in (0, L)
    double width_m = 0.01;        // pad length along the string, m
    double mass_kg = 5e-3;        // M_f
    double stiffness = 1e5;       // K_f of the whole pad, N/m^alpha_f
    double exponent = 1.0;        // alpha_f >= 1
    double loss = 20.0;           // lambda_f, s/m: loss force lambda_f K_f eta^alpha_f d(eta)/dt
    // Pressing force toward the fretboard (N) at times (s): linear in between, held before
    // the first and after the last point. Empty: no force.
    std::vector<std::array<double, 2>> force_profile;
    // The profile was made by `fret = k` (not written by the user): it may outlast a run
    // shortened later (--duration), where a user's own times beyond the run are refused.
    bool default_force = false;
    double initial_gap_m = 0.0;       // pad above the highest pad point of the initial shape
    double initial_velocity = 0.0;    // m/s toward the fretboard
};

// A prescribed force F(t) on the string over a pad (a force gesture, see scheme/ForceProfile.hpp).
struct ForceSpec {
    std::string key = "gesture";
    double position_m = 0.0;   // pad centre, in (0, L)
    double width_m = 0.0;      // 0: a point force at position_m
    double direction = 1.0;    // +1 toward the fretboard ("down"), -1 away from it ("up")
    // Two polarisations: the force leans by this angle from z toward +y, cos(angle) of it
    // along z (with `direction`), sin(angle) along y.
    double angle_deg = 0.0;
    std::vector<std::array<double, 2>> force_profile;  // (t s, F N >= 0), linear in between
};

// A pluck or a pop: a plucker (fingertip or plectrum) on a prescribed path that drags the
// string through a penalty contact of its own and lets it go (see scheme/Pluck.hpp).
struct PluckSpec {
    std::string key = "gesture";
    bool pop = false;              // type = "pop": always away from the fretboard
    double position_m = 0.0;       // pad centre, in (0, L)
    double width_m = 0.008;        // pad length along the string, m
    double direction = -1.0;       // +1 toward the fretboard ("down"), -1 away from it ("up")
    double start_s = 0.0;          // when the plucker appears beside the string and starts to move
    double gap_m = 0.0;            // distance from the string where it appears
    double speed = 0.3;            // m/s along the direction until the release
    double stiffness = 1e5;        // K_p of the whole pad, N/m^exponent
    double exponent = 1.0;
    double loss = 0.0;             // Hunt-Crossley, s/m
    double release_force_n = 0.0;  // lets go once its contact force reaches this (0: never)
    double release_displacement_m = 0.0;  // or once it is this far from the string's rest line (0: never)
    double withdraw_speed = 20.0;  // m/s back along the direction after the release
};

// The second transverse polarisation (y, parallel to the fretboard) and the friction that
// couples it to the contacts along z (see scheme/SecondPolarisation.hpp). count = 1 keeps the
// one-polarisation scheme untouched.
struct PolarisationSettings {
    int count = 1;                   // 1: z only; 2: z and y
    double angle_deg = 0.0;          // excitation direction, from z (0) toward y (90)
    // The y mode table: `table` when given (a measured table, as many modes as z), else the
    // z table with nu_y = frequency_scale nu_z and sigma_y = damping_scale sigma_z.
    ModeTable table;
    double frequency_scale = 1.0;
    double damping_scale = 1.0;
    double friction = 0.0;            // Coulomb coefficient mu_f (contact.friction)
    double friction_velocity = 1e-3;  // regularisation v_eps, m/s (contact.friction_velocity)
    double pickup_angle_deg = 0.0;    // direction of the pickup audio (audio.pickup_angle)
    bool pickup_angle_given = false;
};

// A point obstacle at its exact position (a tanpura's thread, a capo edge): its contact row is
// phi_j(x) at x itself, whatever the mode count. K acts on it over `weight_m` of string (the
// penalty's force per length times that length is the point's force).
struct PointObstacle {
    double x_m = 0.0;
    double height_m = 0.0;
    double weight_m = 0.0;
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
    // Point obstacles at their exact positions, besides the grid's heights (a case whose
    // obstacles are all points; see PointObstacle). Same side and sign convention as the heights.
    std::vector<PointObstacle> point_obstacles;
    // The obstacle lies above the string: contact where u > g, the force pushes down.
    // The scheme runs the mirror image (u -> -u) and mirrors its outputs back.
    bool obstacle_above = false;
    // Initial modal displacement q_j(0) and velocity dq_j/dt(0), j = 1..Nm.
    std::vector<double> initial_displacement;
    std::vector<double> initial_velocity;
    ContactLaw contact;
    PolarisationSettings polarisation;
    RunSettings run;
    std::vector<double> observation_points_m;
    // Fret positions (m, from the nut): a fretboard's x_n as it places them (a case file's, a
    // bench note's); where only heights say where frets are (a measured table), where the
    // obstacle stands out above both neighbouring stretches (see find_frets). Empty on a case
    // without frets.
    std::vector<double> fret_positions_m;
    std::vector<FingerSpec> fingers;
    std::vector<ForceSpec> forces;
    std::vector<PluckSpec> plucks;
    // The case file text this Case was built from (kept in the outputs).
    std::string source_text;
    // What reading the case found doubtful but allowed (shown to the user, kept in summary.json).
    std::vector<std::string> warnings;
    // Why the mode count differs from the case file's (empty: as the file says).
    std::string mode_choice;

    std::size_t mode_count() const { return modes.size(); }
    double grid_step() const { return string.length_m / static_cast<double>(mode_count() + 1); }
    double grid_point(std::size_t i) const { return static_cast<double>(i + 1) * grid_step(); }
    // +1, or -1 when the obstacle is above: multiplies u to get the coordinate in which
    // the contact solve sees an obstacle below.
    double contact_orientation() const { return obstacle_above ? -1.0 : 1.0; }
    // The obstacle on the grid with each exact point at its nearest grid point (for outputs
    // and maps; the solve keeps the points where they are).
    std::vector<double> obstacle_on_grid() const;
    // Whether any grid point or exact point has an obstacle to touch.
    bool has_obstacle() const;

    bool two_polarisations() const { return polarisation.count == 2; }
    // The y polarisation's modes (see PolarisationSettings).
    ModeTable y_modes() const;

    // Removes all losses (sigma_j = 0), for energy-conservation studies.
    void make_lossless();
    // The same string seen from its other end (x -> L - x): its obstacle, frets, fingers,
    // gestures, observation points and initial shape mirrored; its modes unchanged.
    void turn_end_for_end();
    // Adds a finger with the default parameters just behind fret k (1-based); `key` names the
    // setting in messages ("fret", "--fret"). Throws InputError on a case without that fret.
    void add_fret_finger(std::size_t k, const std::string& key);
    // That finger, without adding it (a real-time engine places it at run time).
    FingerSpec fret_finger(std::size_t k, const std::string& key) const;
    // Checks every field; throws InputError naming the first bad one.
    void validate() const;

    // Limits of validate() on derived quantities: the decay of a mode within one step,
    // the phase of its one-step map, and the contact law's exponent (the penalty solve is
    // tested for alpha in [1, 3]; far above, K [g - u]^alpha under- and overflows).
    static constexpr double kMaxSigmaDt = 100.0;
    static constexpr double kMaxOmegaDt = 1e6;
    static constexpr double kMaxExponent = 10.0;
};

// One mode of a bridge that strings rest on (StringsCase): an oscillator of modal mass M, natural
// frequency f and damping ratio zeta, and how much each string's bridge end moves with it (the
// end of string s moves by sum_b participation_b[s] z_b, z_b the mode's coordinate).
struct BridgeModeSpec {
    double mass_kg = 0.0;
    double frequency_hz = 0.0;
    double damping_ratio = 0.0;
    std::vector<double> participation;  // one per string
};

// Several strings whose bridge ends rest on one bridge (scheme/Bridge.hpp): each a whole
// one-string Case (its bridge end at x = L), sharing one time step and one run length.
struct StringsCase {
    std::string name;
    std::string description;
    std::vector<std::string> string_names;
    std::vector<Case> strings;
    std::vector<BridgeModeSpec> bridge;
    RunSettings run;
    std::string source_text;
    // How each string was made from the case it names (what `fretbuzz show` tells).
    struct StringOrigin {
        std::string case_file;               // the [[string]]'s case = "..."
        bool turned = false;                 // mirror = true
        bool at_rest = false;
        double pitch_ratio = 1.0;
        std::vector<std::string> overrides;  // "key = value", one per key of its [string.set]
    };
    std::vector<StringOrigin> origins;

    // A bound on the strings of one case (a sitar's main strings and taraf fit well within it).
    static constexpr std::size_t kMaxStrings = 24;
    static constexpr std::size_t kMaxBridgeModes = 64;
    // Checks the bridge and the strings against each other; throws InputError naming the key.
    void validate() const;
};

// Fret positions (m) on obstacle heights sampled at x_i = (i + 1) dx, for obstacles known by
// their heights alone (a measured profile or scan): see Case::fret_positions_m.
std::vector<double> find_frets(const std::vector<double>& heights, double dx);

// The finger of `fret = k` behind a fret at fret_m, spacing_m past the fret (or nut) before
// it: the default finger (FingerSpec) with its pad 10 mm long, or half the spacing, its near
// edge 15 % of the spacing behind the fret. Its key and pressing force are the caller's.
FingerSpec finger_behind_fret(double fret_m, double spacing_m);
// What that finger presses with once it has landed (N; `fret = k` ramps it up over 5 ms).
constexpr double kFretFingerForce = 5.0;

}  // namespace fretbuzz
