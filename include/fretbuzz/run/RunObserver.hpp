#pragma once
// What a run reports while it goes: observers receive the observation signals at the
// output rate, the energy terms, and (if they ask) audio at a rate of their choice, made by
// the run. Writers are observers; they know nothing of the physics, and the run knows
// nothing of them.
#include <cstddef>
#include <limits>
#include <span>
#include <utility>
#include <string>
#include <vector>

#include "fretbuzz/Case.hpp"

namespace fretbuzz {

struct RunLayout {
    const Case* source = nullptr;
    double dt = 0.0;
    long steps = 0;               // time steps after t = 0
    long output_stride = 1;       // time steps between output rows
    double output_rate_hz = 0.0;  // fs / output_stride
    std::vector<double> observation_points_m;
    std::size_t fingers = 0;      // fingers and gestures on the string (their energy terms are reported)
    int polarisations = 1;        // 2: y is reported too (observation_y, polarisation_energy)
};

struct RunSummary {
    std::string case_name;
    double sample_rate_hz = 0.0;
    double duration_s = 0.0;
    long steps = 0;
    std::size_t modes = 0;
    double output_rate_hz = 0.0;
    double wall_seconds = 0.0;
    double steps_per_second = 0.0;
    double energy_initial_j = 0.0;  // H^{1/2}
    double energy_final_j = 0.0;
    double dissipated_j = 0.0;
    // Relative to E = max(H^{1/2}, the largest |work| so far), see EnergyAudit:
    double max_relative_energy_increase = 0.0;  // largest rise of H - work between output samples, / E
    double max_relative_balance_error = 0.0;    // max |H - work + dissipated - H^{1/2}| / E
    long contact_steps = 0;           // steps where the obstacle pushed on the string
    int max_newton_iterations = 0;
    double mean_points_solved = 0.0;  // contact solves per step
    double free_flight_fraction = 0.0;  // share of steps jumped over (no contact possible)
    double first_contact_s = -1.0;  // of the obstacle's contacts
    double last_contact_s = -1.0;
    bool lossless = false;
    bool screened = true;
    std::string screening;  // whether and why contact screening ran (see choose_screening)
    std::string mode_choice;  // why the mode count differs from the case file's (Case::mode_choice)
    // With fingers: the balance is H - work + dissipated = H^{1/2} (dissipated_j includes
    // finger_loss_j); the terms at the end of the run.
    std::size_t fingers = 0;
    std::size_t gestures = 0;       // force gestures, plucks and pops
    long finger_contact_steps = 0;  // steps where a finger, plucker or force gesture acted
    double work_j = 0.0;            // work of the pressing forces and the pluckers' motions
    double finger_energy_final_j = 0.0;
    double finger_loss_j = 0.0;
    // With two polarisations: energy_final_j includes the y modes' energy, dissipated_j their
    // damping and the friction; the terms at the end of the run.
    int polarisations = 1;
    double energy_y_final_j = 0.0;     // H_y
    double damping_y_j = 0.0;          // damping losses of the y modes
    double friction_j = 0.0;           // friction dissipation (>= 0)
    int max_friction_iterations = 0;
    // The law at the obstacle ("penalty" or "impact") and, for the impact law, its restitution and
    // the energy its impacts took (in dissipated_j too; 0 at e = 1).
    std::string contact_law = "penalty";
    double restitution = 0.0;
    double impact_loss_j = 0.0;
    // Coordinates of the modal state (q, q^n - q^{n-1}, v0; both polarisations) subnormal at the
    // end: 0, since the run flushes them (SubnormalFlush).
    std::size_t subnormal_coordinates = 0;
    // Doubts found reading and planning the case (e.g. modes above fs/2), one line each.
    std::vector<std::string> warnings;
};

// Audio an observer asks the run for (RunObserver::audio_request): the run resamples the
// signal to this rate itself (band-limited, see Resampler) and hands the observer finished
// samples. Velocity is (u^n - u^{n-1}) / dt, what a magnetic pickup senses more nearly than
// the displacement (what an optical sensor sees).
enum class AudioSignal { displacement, velocity };

struct AudioRequest {
    double rate_hz = 0.0;  // samples per second; 0: no audio
    AudioSignal signal = AudioSignal::displacement;
    // The direction the signal is taken along, in degrees from z (the obstacle's normal)
    // toward y: 0 is z alone, 90 is y alone, others cos(a) u_z + sin(a) u_y. Other than 0 only
    // with two polarisations, and for the displacement.
    double angle_deg = 0.0;
};

class RunObserver {
public:
    virtual ~RunObserver() = default;
    virtual void begin(const RunLayout&) {}
    // u at each observation point at t (output rate, from t = 0).
    virtual void observation(double, std::span<const double>) {}
    // Force of the string on its bridge end (x = L) at t, N, positive in the direction of +u:
    // what a bridge pickup senses (same times as observation()).
    virtual void bridge_force(double, double) {}
    // H^{n-1/2}, its contact part and the cumulative dissipated energy, at t = (n - 1/2) dt.
    virtual void energy(double, double, double, double) {}
    // With two polarisations, just before each observation() and energy(): y at each
    // observation point (m; never mirrored), and the y energy terms (J).
    virtual void observation_y(double, std::span<const double>) {}
    virtual void polarisation_energy(double /*energy_y*/, double /*damping_y*/, double /*friction*/) {}
    // With fingers, just before each energy(): the fingers' part of H, the work of the
    // external forces so far, and the fingers' part of the dissipated energy.
    virtual void finger_energy(double /*finger_energy*/, double /*work*/, double /*finger_loss*/) {}
    // With fingers or gestures, with finger_energy(): the height of each finger's pad and of
    // each plucker (m, the case's orientation), in the order fingers, force gestures,
    // plucks; NaN where there is none (a force gesture, a plucker not yet there or gone).
    virtual void played_heights(std::span<const double> /*heights*/) {}
    // Every step with a non-zero contact force: (grid index, force per length in N/m).
    virtual void contacts(double /*t*/, std::span<const std::pair<std::size_t, double>> /*forces*/) {}
    // String shapes on the grid at this rate (Hz), from t = 0 up to snapshot_until_s(); 0 for none.
    virtual double snapshot_rate_hz() const { return 0.0; }
    virtual double snapshot_until_s() const { return std::numeric_limits<double>::infinity(); }
    virtual void snapshot(double /*t*/, std::span<const double> /*x*/, std::span<const double> /*u*/) {}
    // Audio: asked once, after begin(); a rate of 0 asks for none. The run then calls audio()
    // with the finished samples in order, from sample 0 (t = 0) to the run's end (at most
    // round(duration x rate) + 1 samples), each call going on where the last one stopped:
    // `samples` holds frames of one value per observation point (in the case's order),
    // `first_sample` is the first frame's index. The run may make these calls from a thread of
    // its own, while it makes the other calls from the caller's: never two audio() calls at
    // once, all of them after begin() and before finish().
    virtual AudioRequest audio_request() const { return {}; }
    virtual void audio(long /*first_sample*/, std::span<const double> /*samples*/) {}
    virtual void finish(const RunSummary&) {}
};

}  // namespace fretbuzz
