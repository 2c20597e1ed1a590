#include "fretbuzz/Case.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <sstream>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/RunBounds.hpp"
#include "fretbuzz/model/PinnedStringShape.hpp"

namespace fretbuzz {

bool Case::has_obstacle() const {
    return !point_obstacles.empty() || std::any_of(obstacle_height_m.begin(), obstacle_height_m.end(), [](double g) { return std::isfinite(g); });
}

std::vector<double> Case::obstacle_on_grid() const {
    std::vector<double> g = obstacle_height_m;
    const double toward = contact_orientation();
    for (const PointObstacle& p : point_obstacles) {
        const double index = std::clamp(std::round(p.x_m / grid_step()) - 1.0, 0.0, static_cast<double>(g.size()) - 1.0);
        double& gi = g[static_cast<std::size_t>(index)];
        if (!std::isfinite(gi) || toward * p.height_m > toward * gi) gi = p.height_m;
    }
    return g;
}

ContactLawKind contact_law_named(const std::string& word, const std::string& key) {
    if (word == "penalty") return ContactLawKind::penalty;
    if (word == "impact") return ContactLawKind::impact;
    throw InputError(key + " = \"" + word + "\": must be \"penalty\" (K [eta]_+^alpha) or \"impact\" (Newton's law, "
                     "with restitution in [0, 1])");
}

const char* contact_law_name(ContactLawKind law) { return law == ContactLawKind::impact ? "impact" : "penalty"; }

void Case::make_lossless() {
    std::fill(modes.sigma_per_s.begin(), modes.sigma_per_s.end(), 0.0);
    std::fill(polarisation.table.sigma_per_s.begin(), polarisation.table.sigma_per_s.end(), 0.0);
    if (std::isfinite(polarisation.damping_scale)) polarisation.damping_scale = 0.0;
}

void Case::turn_end_for_end() {
    const double length = string.length_m;
    const auto turn = [length](double& x) { x = length - x; };
    // The grid x_i = i L / (Nm + 1) maps onto itself in reverse order.
    std::reverse(obstacle_height_m.begin(), obstacle_height_m.end());
    for (PointObstacle& p : point_obstacles) turn(p.x_m);
    // sin(j pi (L - x) / L) = -(-1)^j sin(j pi x / L): the even modes change sign.
    for (std::vector<double>* q : {&initial_displacement, &initial_velocity})
        for (std::size_t j = 1; j < q->size(); j += 2) (*q)[j] = -(*q)[j];
    for (double& x : observation_points_m) turn(x);
    for (double& x : fret_positions_m) turn(x);
    std::reverse(fret_positions_m.begin(), fret_positions_m.end());
    for (FingerSpec& f : fingers) turn(f.position_m);
    for (ForceSpec& f : forces) turn(f.position_m);
    for (PluckSpec& p : plucks) turn(p.position_m);
}

ModeTable Case::y_modes() const {
    if (polarisation.table.size() > 0) return polarisation.table;
    ModeTable y = modes;
    for (double& f : y.frequency_hz) f *= polarisation.frequency_scale;
    for (double& s : y.sigma_per_s) s *= polarisation.damping_scale;
    return y;
}

namespace {

// Ranges of the fingers' and gestures' parameters (docs/case-format.md says why):
// a finger from 10 mg to 10 kg: M fs^2 and the pressing force's F dt^2 / M stay far from
// overflow and underflow at any rate;
constexpr double kMinFingerMass = 1e-5, kMaxFingerMass = 10.0;
// a Hunt-Crossley loss lambda makes an impact at speed v lose about lambda v of its energy:
// at 1000 s/m even a 1 mm/s touch is fully plastic, and beyond it the contact solves stall;
constexpr double kMaxContactLoss = 1000.0;
// a plucker pad of 1e15 N/m is rigid (1e-14 m under 10 N): stiffer only overflows its powers;
constexpr double kMaxPluckStiffness = 1e15;
// a gesture slower than 0.1 mm/s takes more than a minute to pull a string by 6 mm.
constexpr double kMinGestureSpeed = 1e-4;
// each force gesture keeps two vectors of the mode count (its load on every mode, and that
// load's displacement on the grid): a hand has a few, and this bounds what a case can ask for.
constexpr std::size_t kMaxForceGestures = 64;
// Pluckers: each keeps two vectors of the mode count and is one more unknown of the joint contact
// solve, whose room is planned for all of them (no plucker moves another contact off its place).
constexpr std::size_t kMaxPluckGestures = 64;

void require_length(const std::string& name, std::size_t actual, std::size_t expected) {
    if (actual != expected) {
        std::ostringstream out;
        out << name << " has " << actual << " values but the case has " << expected << " modes";
        throw InputError(out.str());
    }
}

void check_initial_shape_clears_obstacle(const Case& c) {
    const std::vector<double> u0 = pinned_string_shape_on_grid(c.string.length_m, c.initial_displacement);
    // Touching is allowed; penetrating beyond round-off of the shape is not.
    double scale = 0.0;
    for (double v : u0) scale = std::max(scale, std::abs(v));
    const double tolerance = 1e-12 * scale;
    const double s = c.contact_orientation();
    const auto check = [&](const char* what, double x, double u, double g) {
        if (!(s * u < s * g - tolerance)) return;
        std::ostringstream out;
        out.precision(6);
        out << "initial shape penetrates " << what << " at x = " << x << " m: u = " << u << " m is "
            << (c.obstacle_above ? "above" : "below") << " the obstacle height " << g
            << " m; the initial displacement must satisfy u(x, 0) " << (c.obstacle_above ? "<=" : ">=")
            << " g(x) everywhere";
        throw InputError(out.str());
    };
    for (std::size_t i = 0; i < u0.size(); ++i)
        if (std::isfinite(c.obstacle_height_m[i]))  // else nothing to touch here
            check("the obstacle", c.grid_point(i), u0[i], c.obstacle_height_m[i]);
    // Exact points: the shape at x itself (the same direct sine sum).
    for (const PointObstacle& p : c.point_obstacles) {
        double u = 0.0;
        for (std::size_t j = 0; j < c.initial_displacement.size(); ++j)
            u += c.initial_displacement[j] * std::sqrt(2.0 / c.string.length_m) *
                 std::sin(static_cast<double>(j + 1) * std::numbers::pi * p.x_m / c.string.length_m);
        check("the point obstacle", p.x_m, u, p.height_m);
    }
}

void check_pad(const std::string& k, double position, double width, bool point_allowed, const Case& c) {
    const double length = c.string.length_m;
    require_finite(k + ".position (m)", position);
    if (!(position > 0.0 && position < length))
        throw InputError(out_of_range_message(k + ".position (m)", position,
                                              "must lie inside the string, in (0, L) = (0, " + std::to_string(length) +
                                                  ") m"));
    if (point_allowed)
        require_non_negative(k + ".width (m)", width);
    else
        require_positive(k + ".width (m)", width);
    if (!(position - 0.5 * width > 0.0 && position + 0.5 * width < length))
        throw InputError(out_of_range_message(k + ".width (m)", width,
                                              "the pad [position - width/2, position + width/2] must stay inside "
                                              "(0, L): it overlaps an end of the string"));
}

// A profile's points may lie past the run's end (a case shortened with --duration keeps its
// profiles): only the part within the run acts.
void check_force_profile(const std::string& k, const std::vector<std::array<double, 2>>& profile) {
    if (profile.empty())
        throw InputError(k + ".force = []: an empty profile never presses; give a force in N or points [[t_s, F_N], ...]");
    for (std::size_t p = 0; p < profile.size(); ++p) {
        const std::string item = k + ".force[" + std::to_string(p) + "]";
        const double t = profile[p][0], force = profile[p][1];
        require_finite(item + "[0] (time, s)", t);
        if (!(t >= 0.0))
            throw InputError(out_of_range_message(item + "[0] (time, s)", t, "must be >= 0 (from the start of the run)"));
        if (p > 0 && !(t > profile[p - 1][0]))
            throw InputError(out_of_range_message(item + "[0] (time, s)", t, "must increase from point to point"));
        require_non_negative(item + "[1] (force, N)", force);
        if (force > 1000.0) throw InputError(out_of_range_message(item + "[1] (force, N)", force, "must be in [0, 1000] N"));
    }
}

void require_in(const std::string& name, double value, double lo, double hi, const char* unit) {
    require_finite(name, value);
    if (!(value >= lo && value <= hi)) {
        std::ostringstream allowed;
        allowed << "must be in [" << lo << ", " << hi << "] " << unit;
        throw InputError(out_of_range_message(name, value, allowed.str()));
    }
}

// The pad's stiffness as the finger's solve sees it: k = dF/d(eta) where the pad carries the
// largest pressing force of the profile (at least 1 N), exponent alpha: alpha K^(1/alpha) F^(1-1/alpha).
double pad_stiffness(const FingerSpec& f) {
    double force = 1.0;
    for (const auto& point : f.force_profile) force = std::max(force, point[1]);
    return f.exponent * std::pow(f.stiffness, 1.0 / f.exponent) * std::pow(force, 1.0 - 1.0 / f.exponent);
}

void check_finger(const FingerSpec& f, const Case& c) {
    const std::string& k = f.key;
    check_pad(k, f.position_m, f.width_m, false, c);
    require_in(k + ".mass (kg)", f.mass_kg, kMinFingerMass, kMaxFingerMass, "kg");
    require_positive(k + ".stiffness (N/m^exponent)", f.stiffness);
    require_at_least(k + ".exponent", f.exponent, 1.0);
    if (f.exponent > 3.0) throw InputError(out_of_range_message(k + ".exponent", f.exponent, "must be in [1, 3]"));
    // The finger on its pad is a mass on a spring of angular frequency sqrt(k / M): the step
    // must resolve it (omega dt <= 1). Past that the nested contact solve of the finger is
    // ill-conditioned (its Newton steps stall short of round-off) and the motion is not
    // resolved anyway.
    const double fs = c.run.sample_rate_hz;
    const double most = f.mass_kg * fs * fs;
    if (const double k_pad = pad_stiffness(f); !(k_pad <= most)) {
        std::ostringstream allowed;
        allowed.precision(4);
        allowed << "with mass " << f.mass_kg << " kg at run.fs = " << fs << " Hz the pad's resonance sqrt(k/M) = "
                << std::sqrt(k_pad / f.mass_kg) << " rad/s (k = " << k_pad
                << " N/m under the largest pressing force) must stay below fs: k <= M fs^2 = " << most
                << " N/m (lower the stiffness, raise the mass or raise run.fs)";
        throw InputError(out_of_range_message(k + ".stiffness (N/m^exponent)", f.stiffness, allowed.str()));
    }
    require_in(k + ".loss (s/m)", f.loss, 0.0, kMaxContactLoss, "s/m");
    require_non_negative(k + ".gap (m)", f.initial_gap_m);
    if (f.initial_gap_m > 0.05) throw InputError(out_of_range_message(k + ".gap (m)", f.initial_gap_m, "must be in [0, 0.05] m"));
    require_finite(k + ".velocity (m/s)", f.initial_velocity);
    if (std::abs(f.initial_velocity) > 100.0)
        throw InputError(out_of_range_message(k + ".velocity (m/s)", f.initial_velocity, "must be in [-100, 100] m/s"));
    // No profile: no pressing force (a thumb that strikes and bounces off).
    if (!f.force_profile.empty()) check_force_profile(k, f.force_profile);
}

void check_pluck(const PluckSpec& f, const Case& c) {
    const std::string& k = f.key;
    check_pad(k, f.position_m, f.width_m, false, c);
    require_in(k + ".time (s)", f.start_s, 0.0, c.run.duration_s, "s (within the run)");
    require_in(k + ".gap (m)", f.gap_m, 0.0, 0.05, "m");
    require_in(k + ".speed (m/s)", f.speed, kMinGestureSpeed, 100.0, "m/s");
    require_positive(k + ".stiffness (N/m^exponent)", f.stiffness);
    require_in(k + ".stiffness (N/m^exponent)", f.stiffness, 0.0, kMaxPluckStiffness, "N/m^exponent");
    require_in(k + ".exponent", f.exponent, 1.0, 3.0, "");
    require_in(k + ".loss (s/m)", f.loss, 0.0, kMaxContactLoss, "s/m");
    require_in(k + ".release_force (N)", f.release_force_n, 0.0, 1000.0, "N");
    require_in(k + ".release_displacement (m)", f.release_displacement_m, 0.0, 0.05, "m");
    if (!(f.release_force_n > 0.0 || f.release_displacement_m > 0.0))
        throw InputError(k + ".release_force (N) and " + k +
                         ".release_displacement (m): give at least one > 0 (when the plucker lets go)");
    require_in(k + ".withdraw_speed (m/s)", f.withdraw_speed, kMinGestureSpeed, 1000.0, "m/s");
}

void check_pads_apart(const Case& c) {
    struct Pad {
        const std::string* key;
        double position, width;
    };
    std::vector<Pad> pads;
    for (const FingerSpec& f : c.fingers) pads.push_back({&f.key, f.position_m, f.width_m});
    for (const ForceSpec& f : c.forces) pads.push_back({&f.key, f.position_m, f.width_m});
    for (const PluckSpec& f : c.plucks) pads.push_back({&f.key, f.position_m, f.width_m});
    for (std::size_t a = 0; a < pads.size(); ++a)
        for (std::size_t b = a + 1; b < pads.size(); ++b)
            if (std::abs(pads[a].position - pads[b].position) < 0.5 * (pads[a].width + pads[b].width) + c.grid_step())
                throw InputError(out_of_range_message(*pads[b].key + ".position (m)", pads[b].position,
                                                      "its pad overlaps the pad of " + *pads[a].key +
                                                          " (pads must be apart by more than one grid step)"));
}

// Each mode's step at run.fs (`what` names the table in messages).
void check_mode_steps(const ModeTable& modes, double fs, const std::string& what) {
    const double dt = 1.0 / fs;
    for (std::size_t j = 0; j < modes.size(); ++j) {
        const std::string mode = what + "mode " + std::to_string(j + 1);
        // e^{-sigma dt} and sinh of the overdamped rate overflow or underflow near sigma dt = 700;
        // a mode that loses e^-100 of its amplitude in one step is not a physical input anyway.
        const double sigma_dt = modes.sigma_per_s[j] * dt;
        if (!(sigma_dt <= Case::kMaxSigmaDt)) {
            std::ostringstream allowed;
            allowed << "sigma * dt = " << sigma_dt << " at run.fs = " << fs << " Hz; must be <= " << Case::kMaxSigmaDt
                    << " (lower the damping or raise fs)";
            throw InputError(out_of_range_message(mode + " sigma_per_s", modes.sigma_per_s[j], allowed.str()));
        }
        // The one-step map evaluates sin(omega dt): far above fs its phase is round-off.
        const double omega_dt = 2.0 * std::numbers::pi * modes.frequency_hz[j] * dt;
        if (!(omega_dt <= Case::kMaxOmegaDt)) {
            std::ostringstream allowed;
            allowed << "omega * dt = " << omega_dt << " at run.fs = " << fs << " Hz; must be <= " << Case::kMaxOmegaDt;
            throw InputError(out_of_range_message(mode + " frequency_hz", modes.frequency_hz[j], allowed.str()));
        }
    }
}

// Quantities derived from several inputs, checked before a run plans anything: each would
// otherwise overflow deep inside the scheme and surface as a divergence naming nothing.
void check_derived_quantities(const Case& c) {
    const double fs = c.run.sample_rate_hz;
    const double dt = 1.0 / fs;
    if (std::lround(c.run.duration_s * fs) < 1) {
        std::ostringstream allowed;
        allowed << "must be at least one time step, 1/run.fs = " << dt << " s";
        throw InputError(out_of_range_message("run.duration (s)", c.run.duration_s, allowed.str()));
    }
    check_mode_steps(c.modes, fs, "");
    // The second polarisation's modes go through the same one-step map.
    if (c.two_polarisations())
        check_mode_steps(c.y_modes(), fs,
                         c.polarisation.table.size() > 0
                             ? "polarisation_y.table "
                             : "polarisation_y (string's modes times frequency_scale and damping_scale) ");
    // The energy is mu / (2 dt^2) times a sum over modes: both must be representable.
    const double scale = c.string.linear_density / (2.0 * dt * dt);
    if (!std::isfinite(scale)) {
        std::ostringstream allowed;
        allowed << "with run.fs = " << fs << " Hz the energy scale mu fs^2 / 2 overflows; must keep mu * fs^2 finite";
        throw InputError(out_of_range_message("string.mu (linear density, kg/m)", c.string.linear_density, allowed.str()));
    }
    double initial = 0.0;  // (1/2) mu sum_j (v_j^2 + omega_j^2 q_j^2)
    for (std::size_t j = 0; j < c.mode_count(); ++j) {
        const double omega = 2.0 * std::numbers::pi * c.modes.frequency_hz[j];
        const double q = c.initial_displacement[j] * omega, v = c.initial_velocity[j];
        initial += 0.5 * c.string.linear_density * (v * v + q * q);
    }
    if (!std::isfinite(initial))
        throw InputError(out_of_range_message(
            "string.mu (linear density, kg/m)", c.string.linear_density,
            "with this initial displacement and velocity the initial energy overflows; must keep the energy finite"));
}

// Two polarisations (see PolarisationSettings): every key that needs the second one is refused
// without it, rather than silently ignored.
void check_polarisations(const Case& c) {
    const PolarisationSettings& p = c.polarisation;
    if (p.count != 1 && p.count != 2)
        throw InputError(out_of_range_message("string.polarisations", p.count, "must be 1 or 2"));
    require_finite("excitation.angle (degrees)", p.angle_deg);
    if (std::abs(p.angle_deg) > 360.0)
        throw InputError(out_of_range_message("excitation.angle (degrees)", p.angle_deg, "must be in [-360, 360]"));
    require_finite("audio.pickup_angle (degrees)", p.pickup_angle_deg);
    if (std::abs(p.pickup_angle_deg) > 360.0)
        throw InputError(out_of_range_message("audio.pickup_angle (degrees)", p.pickup_angle_deg, "must be in [-360, 360]"));
    require_finite("contact.friction", p.friction);
    if (!(p.friction >= 0.0 && p.friction <= 10.0))
        throw InputError(out_of_range_message("contact.friction (Coulomb coefficient)", p.friction, "must be in [0, 10]"));
    require_finite("contact.friction_velocity (m/s)", p.friction_velocity);
    if (!(p.friction_velocity >= 1e-9 && p.friction_velocity <= 10.0))
        throw InputError(out_of_range_message("contact.friction_velocity (m/s)", p.friction_velocity,
                                              "must be in [1e-9, 10]"));
    if (!(p.frequency_scale >= 0.5 && p.frequency_scale <= 2.0))
        throw InputError(out_of_range_message("polarisation_y.frequency_scale", p.frequency_scale, "must be in [0.5, 2]"));
    if (!(p.damping_scale >= 0.0 && p.damping_scale <= 100.0))
        throw InputError(out_of_range_message("polarisation_y.damping_scale", p.damping_scale, "must be in [0, 100]"));
    if (p.table.size() > 0) {
        if (p.table.size() != c.mode_count())
            throw InputError("polarisation_y.table has " + std::to_string(p.table.size()) +
                             " modes but string.modes = " + std::to_string(c.mode_count()) +
                             ": both polarisations share one modal basis and need the same mode count");
        p.table.validate();
    }
    for (const ForceSpec& f : c.forces) {
        require_finite(f.key + ".angle (degrees)", f.angle_deg);
        if (std::abs(f.angle_deg) > 360.0)
            throw InputError(out_of_range_message(f.key + ".angle (degrees)", f.angle_deg, "must be in [-360, 360]"));
        if (f.angle_deg != 0.0 && !c.two_polarisations())
            throw InputError(f.key + ".angle = " + std::to_string(f.angle_deg) +
                             " needs string.polarisations = 2 (or --polarisations 2)");
    }
    if (c.two_polarisations()) return;
    const auto needs_two = [](const std::string& key) {
        return InputError(key + " needs string.polarisations = 2 (or --polarisations 2)");
    };
    if (p.angle_deg != 0.0) throw needs_two("excitation.angle = " + std::to_string(p.angle_deg));
    if (p.friction != 0.0) throw needs_two("contact.friction = " + std::to_string(p.friction));
    if (p.pickup_angle_given) throw needs_two("audio.pickup_angle");
}

// The impact law steps the string against rigid obstacles (NewtonImpact), force gestures
// loading it: parts with contacts of their own (fingers, pluckers) would need their pads inside
// its complementarity problem, and y its friction cone, which it does not have yet.
void refuse_beside_impact(const Case& c) {
    const auto refuse = [](const std::string& key, const std::string& why) {
        return InputError(key + " cannot be used with contact.law = \"impact\": " + why +
                          " (use contact.law = \"penalty\")");
    };
    if (!c.fingers.empty())
        throw refuse(c.fingers[0].key, "a finger's pad is a penalty contact of its own, not yet in the impact solve");
    if (!c.plucks.empty())
        throw refuse(c.plucks[0].key, "a plucker's pad is a penalty contact of its own, not yet in the impact solve");
    if (c.two_polarisations())
        throw refuse("string.polarisations = 2", "the impact law has no friction cone for y yet");
}

}  // namespace

std::vector<double> find_frets(const std::vector<double>& heights, double dx) {
    // A fret is a stretch of points (one for a plain fret, several for a crowned one) that
    // stands at least 0.1 mm above the points on both sides of it: far more than any neck
    // relief changes over one grid step, far less than any fret's height.
    constexpr double kStep = 1e-4;
    std::vector<double> frets;
    const std::size_t n = heights.size();
    for (std::size_t i = 1; i + 1 < n; ++i) {
        if (!std::isfinite(heights[i]) || !(heights[i] - heights[i - 1] > kStep)) continue;
        std::size_t j = i;
        while (j + 1 < n && std::isfinite(heights[j + 1]) && std::abs(heights[j + 1] - heights[j]) <= kStep) ++j;
        if (j + 1 < n && heights[j] - heights[j + 1] > kStep)
            frets.push_back(0.5 * static_cast<double>(i + j + 2) * dx);
        i = j;
    }
    return frets;
}

void Case::add_fret_finger(std::size_t k, const std::string& key) { fingers.push_back(fret_finger(k, key)); }

FingerSpec Case::fret_finger(std::size_t k, const std::string& key) const {
    if (fret_positions_m.empty())
        throw InputError(key + " = " + std::to_string(k) +
                         ": this case has no frets (its obstacle has no fret standing out of the fingerboard); "
                         "place a finger with [[finger]] position = ... instead");
    if (k < 1 || k > fret_positions_m.size())
        throw InputError(out_of_range_message(key, static_cast<double>(k),
                                              "must be a fret of this case, in [1, " +
                                                  std::to_string(fret_positions_m.size()) + "]"));
    const double fret = fret_positions_m[k - 1];
    FingerSpec f = finger_behind_fret(fret, fret - (k > 1 ? fret_positions_m[k - 2] : 0.0));
    f.key = key + " = " + std::to_string(k) + " (finger)";
    f.force_profile = {{0.0, 0.0}, {std::min(0.005, 0.5 * run.duration_s), kFretFingerForce}};
    f.default_force = true;
    return f;
}

FingerSpec finger_behind_fret(double fret_m, double spacing_m) {
    FingerSpec f;  // defaults: see FingerSpec and the case files' comments
    f.width_m = std::min(0.01, 0.5 * spacing_m);
    // Just behind the fret: the pad's near edge 15 % of the fret spacing from it.
    f.position_m = fret_m - 0.15 * spacing_m - 0.5 * f.width_m;
    return f;
}

void check_run_bounds(const RunSettings& run, const std::string& audio_key) {
    require_positive("run.fs (sample rate, Hz)", run.sample_rate_hz);
    require_positive("run.duration (s)", run.duration_s);
    // Counted as the run counts them (rounded): with none nothing runs, and 4e9 are days of work.
    const double steps = run.sample_rate_hz * run.duration_s;
    if (!(std::round(steps) >= 1.0 && steps <= 4e9))
        throw InputError(out_of_range_message("run.fs * run.duration (number of steps)", steps, "must be in [1, 4e9]"));
    if (run.output_rate_hz) {
        require_positive("run.output_rate (Hz)", *run.output_rate_hz);
        if (*run.output_rate_hz > run.sample_rate_hz)
            throw InputError(out_of_range_message("run.output_rate (Hz)", *run.output_rate_hz,
                                                  "must not exceed run.fs = " + std::to_string(run.sample_rate_hz) +
                                                      " Hz (set a lower output rate, or \"native\")"));
    }
    // The resampler's and the audio files' range (what libsoxr and WAV players take).
    if (!(run.audio_rate_hz >= 8000.0 && run.audio_rate_hz <= 384000.0))
        throw InputError(out_of_range_message(audio_key + " (Hz)", run.audio_rate_hz, "must be in [8000, 384000]"));
}

void Case::validate() const {
    require_positive("string.L (length, m)", string.length_m);
    require_positive("string.T (tension, N)", string.tension_n);
    require_positive("string.mu (linear density, kg/m)", string.linear_density);
    modes.validate();
    const std::size_t n = mode_count();
    require_length("obstacle heights", obstacle_height_m.size(), n);
    require_length("initial displacement", initial_displacement.size(), n);
    require_length("initial velocity", initial_velocity.size(), n);
    for (std::size_t i = 0; i < n; ++i) {
        const double g = obstacle_height_m[i];
        if (std::isnan(g) || g == std::numeric_limits<double>::infinity())
            throw InputError(out_of_range_message("obstacle height at x = " + std::to_string(grid_point(i)) + " m", g,
                                                  "must be finite (or -inf for no obstacle)"));
        require_finite("initial displacement of mode " + std::to_string(i + 1), initial_displacement[i]);
        require_finite("initial velocity of mode " + std::to_string(i + 1), initial_velocity[i]);
    }
    for (std::size_t k = 0; k < point_obstacles.size(); ++k) {
        const PointObstacle& p = point_obstacles[k];
        const std::string item = "obstacle point " + std::to_string(k);
        if (!(p.x_m > 0.0 && p.x_m < string.length_m))
            throw InputError(out_of_range_message(item + " x (m)", p.x_m, "must lie inside the string, in (0, L)"));
        if (!(std::abs(p.height_m) <= 0.1))
            throw InputError(out_of_range_message(item + " height (m)", p.height_m, "must be in [-0.1, 0.1] m"));
        if (!(p.weight_m > 0.0 && p.weight_m <= string.length_m))
            throw InputError(out_of_range_message(item + " width (m)", p.weight_m, "must be in (0, L]"));
    }
    require_positive("contact.K (penalty stiffness)", contact.stiffness);
    require_at_least("contact.alpha (penalty exponent)", contact.exponent, 1.0);
    if (contact.exponent > kMaxExponent)
        throw InputError(out_of_range_message("contact.alpha (penalty exponent)", contact.exponent,
                                              "must be in [1, " + std::to_string(static_cast<int>(kMaxExponent)) + "]"));
    if (!(contact.restitution >= 0.0 && contact.restitution <= 1.0))
        throw InputError(out_of_range_message("contact.restitution (Newton's coefficient)", contact.restitution,
                                              "must be in [0, 1]"));
    if (contact.law == ContactLawKind::impact) refuse_beside_impact(*this);
    check_run_bounds(run);
    if (observation_points_m.empty()) throw InputError("observe: at least one observation point is required");
    for (double x : observation_points_m) {
        require_finite("observation point x (m)", x);
        if (!(x > 0.0 && x < string.length_m))
            throw InputError(out_of_range_message("observation point x (m)", x,
                                                  "must lie inside the string, in (0, L) = (0, " +
                                                      std::to_string(string.length_m) + ")"));
    }
    check_derived_quantities(*this);
    check_initial_shape_clears_obstacle(*this);
    for (const FingerSpec& f : fingers) check_finger(f, *this);
    if (forces.size() > kMaxForceGestures)
        throw InputError("gesture: " + std::to_string(forces.size()) + " force gestures; at most " +
                         std::to_string(kMaxForceGestures) + " are allowed");
    for (const ForceSpec& f : forces) {
        check_pad(f.key, f.position_m, f.width_m, true, *this);
        check_force_profile(f.key, f.force_profile);
    }
    if (plucks.size() > kMaxPluckGestures)
        throw InputError("gesture: " + std::to_string(plucks.size()) + " pluck or pop gestures; at most " +
                         std::to_string(kMaxPluckGestures) + " are allowed");
    for (const PluckSpec& f : plucks) check_pluck(f, *this);
    check_pads_apart(*this);
    check_polarisations(*this);
}

}  // namespace fretbuzz

namespace fretbuzz {

void StringsCase::validate() const {
    check_run_bounds(run, "run.audio_rate");
    if (strings.empty()) throw InputError("string: a case with a bridge needs at least one [[string]]");
    if (strings.size() > kMaxStrings)
        throw InputError("string: " + std::to_string(strings.size()) + " strings; at most " +
                         std::to_string(kMaxStrings) + " rest on one bridge");
    for (std::size_t s = 0; s < strings.size(); ++s) {
        strings[s].validate();
        // Each string's end is a load known before its step (BridgeEnd), which the impact law's
        // complementarity problem does not take yet.
        if (strings[s].contact.law == ContactLawKind::impact)
            throw InputError("string[" + std::to_string(s) + "] contact.law = \"impact\": strings on a bridge step "
                             "the penalty law only (use contact.law = \"penalty\")");
    }
    if (bridge.empty()) throw InputError("bridge.mode: a bridge needs at least one [[bridge.mode]]");
    if (bridge.size() > kMaxBridgeModes)
        throw InputError("bridge.mode: " + std::to_string(bridge.size()) + " modes; at most " +
                         std::to_string(kMaxBridgeModes));
    for (std::size_t b = 0; b < bridge.size(); ++b) {
        const BridgeModeSpec& m = bridge[b];
        const std::string key = "bridge.mode[" + std::to_string(b) + "].";
        require_positive(key + "mass_kg", m.mass_kg);
        require_positive(key + "frequency_hz", m.frequency_hz);
        require_non_negative(key + "damping_ratio", m.damping_ratio);
        if (m.participation.size() != strings.size())
            throw InputError(key + "participation: " + std::to_string(m.participation.size()) +
                             " values for " + std::to_string(strings.size()) + " strings (one per [[string]])");
        for (std::size_t s = 0; s < strings.size(); ++s)
            require_finite(key + "participation[" + std::to_string(s) + "]", m.participation[s]);
    }
    // A string that no mode moves is on no bridge: it would sound alone, which a case with a
    // bridge does not mean.
    for (std::size_t s = 0; s < strings.size(); ++s) {
        bool on_bridge = false;
        for (const BridgeModeSpec& m : bridge) on_bridge = on_bridge || m.participation[s] != 0.0;
        if (!on_bridge)
            throw InputError("string[" + std::to_string(s) + "] (\"" + string_names[s] +
                             "\"): on no bridge (every bridge.mode's participation for it is 0)");
    }
    for (std::size_t s = 0; s < strings.size(); ++s) {
        if (strings[s].run.sample_rate_hz != run.sample_rate_hz)
            throw InputError("string[" + std::to_string(s) + "].run.fs: strings on one bridge share one rate (" +
                             std::to_string(run.sample_rate_hz) + " Hz)");
        if (strings[s].run.duration_s != run.duration_s)
            throw InputError("string[" + std::to_string(s) + "].run.duration: strings on one bridge share one run length (" +
                             std::to_string(run.duration_s) + " s)");
    }
}

}  // namespace fretbuzz
