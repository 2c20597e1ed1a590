#pragma once
// A real-time voice: one string of a Case, rendered in blocks of audio at the host rate while
// events arrive between blocks (plucks, mute, changes of contact law, damping or pickup).
//
// It runs the offline scheme itself (Plan, Stepper, PenaltyContact: no second physics) at an
// internal rate M times the host rate, M an integer chosen at set-up so that every mode kept
// lies below the internal Nyquist frequency (the aliasing check of SamplingCheck passes; modes
// that would need more than the largest allowed M are dropped). The default keeps every mode
// up to M = 8: dropping modes changes the buzz by more than the rate (RateAccuracy measures
// it; the numbers are by choose_rate in InternalRate.cpp). It decimates the pickup
// signal by M through a band-limited FIR (Decimator). While no point can touch, it flies over
// each host sample stepping only the modes below the host's Nyquist frequency (FreeFlight).
//
// On a case with frets a finger plays notes: the library's Finger (scheme/Finger.hpp, the
// finger that `fret = k` puts on the string offline), placed just behind fret k and pressed
// at run time, lifted again to let the open string ring.
//
// The audio path (process and every event) allocates nothing and takes no lock; denormals
// are flushed to zero while it runs. The discrete energy is the guard: without input it can
// only decrease, so if H + dissipated - W (W: the pressing force's work; dissipated counts the
// finger's contact loss) ever exceeds the energy put in (every pluck, and every parameter
// change, counted), or a sample is not finite, the voice is silenced and counted.
#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/realtime/Decimator.hpp"
#include "fretbuzz/realtime/EnergyGuard.hpp"
#include "fretbuzz/realtime/FretHand.hpp"
#include "fretbuzz/scheme/FreeFlight.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/Stepper.hpp"

namespace fretbuzz {

struct EngineOptions {
    double host_rate_hz = 48000.0;
    int oversampling = 0;          // M; 0: the smallest that keeps every mode below 0.45 M fs
    int max_oversampling = 8;      // largest M chosen automatically (cost grows with M; fewer
                                   // modes change the buzz: see choose_rate in InternalRate.cpp)
    std::size_t max_modes = 0;     // 0: the case's (fewer if M cannot reach them)
    bool free_flight = true;       // fly while no contact is possible (false: step every mode)
    bool start_from_case = false;  // start from the case's initial state (else at rest)
    int taps_per_phase = 64;       // decimation filter length / M
    double pickup_m = -1.0;        // where the signal is read; < 0: the case's first observation point
    double gain_per_m = 1000.0;    // output sample per metre of displacement
};

// An excitation added to the sounding string: a raised-cosine bump of the given width
// centred at position_m, in velocity (a pluck or a pick: strength in m/s) or in
// displacement (a pop: strength in m).
struct Strike {
    double position_m = 0.0;
    double strength = 0.5;
    double width_m = 0.01;
    bool displacement = false;
};

// value clamped to [low, high] (NaN: low), each move counted in `count`.
double clamp_counted(double value, double low, double high, long& count);
// The strike's bump in modal coordinates, dx S^T u, added to `target` (a displacement or a
// velocity, as s says) on c's string planned by `plan`; its width, position and strength are
// clamped to the string (counted in `clamped`). `row` is scratch of c.mode_count().
void add_strike(const Strike& s, const Case& c, const Plan& plan, std::vector<double>& row,
                std::vector<double>& target, long& clamped);

// What the energy guard and the clamps saw (read by front ends to log, outside the audio path).
struct EngineHealth {
    long resets = 0;         // times the voice was silenced by the guard
    long clamped = 0;        // control values moved into their range
    long solver_failures = 0;
};

// FFTW runs the sine transform of n modes as a real DFT of 2(n + 1) points. Where n + 1 has
// a prime factor above 31 its plans (Rader's and Bluestein's algorithms, buffered solvers)
// allocate memory every time they run: the engine then evaluates the string by rows of S only.
// For every other n up to 4096 a transform allocates nothing (tests/realtime checks each).
bool sine_transform_allocates(std::size_t n);

// A voice's modal damping under its damping scale and mute (Engine::set_damping_scale, mute):
// sigma = base scale, or, muted, base scale x Engine::kMuteScale plus a floor that damps even a
// lossless string.
void voice_damping(std::span<const double> base, double scale, bool muted, std::span<double> sigma);

class Engine {
public:
    // The costly set-up: plans the case at the internal rate and warms every buffer.
    // InputError for bad options (named, with their range).
    Engine(const Case& c, const EngineOptions& options = {});
    Engine(const Engine&) = delete;
    Engine& operator=(const Engine&) = delete;

    // Renders out.size() host samples (any size). Allocates nothing.
    void process(std::span<float> out);
    // Renders out.size() internal steps of the pickup displacement (m), undecimated (tests).
    void render_internal(std::span<double> out);

    // Events, between blocks; none allocates. Values out of range are clamped (health().clamped).
    void strike(const Strike& s);
    void set_damping_scale(double scale);  // multiplies every sigma_j, in [0, 1000]
    void mute(bool on);                    // damping scale x kMuteScale while on
    void set_contact_law(double stiffness, double exponent);  // K in [1, 1e16], alpha in [1, 3]
    void set_pickup(double x_m);           // in (0, L)
    // Raises the obstacle (frets, bridge) by `offset` metres toward the string: more buzz.
    void set_obstacle_offset(double offset_m);  // in [-5 mm, 1 mm]
    // Fingering (fret_count() > 0): finger_down(k) lands the finger at rest on the string just
    // behind fret k (where `fret = k` puts it) and ramps its pressing force up as `fret = k`
    // does; a finger already down moves there (a new note). k = 0 lifts it; k outside
    // [0, fret_count()] is clamped. finger_up ramps the force down over the same time: the
    // string throws the finger off, and once it has left (checked after each block) it is taken
    // off the string, which rings open again. False if the case has no frets.
    bool finger_down(int fret);
    void finger_up();
    // Brings the string to rest at once (a voice taken for another note); not a guard reset.
    void stop();

    int oversampling() const { return factor_; }
    // Why the internal rate is what it is (for a front end to print).
    const char* rate_choice() const { return rate_choice_; }
    // The output lags the string by the decimation filter's group delay: this many host
    // samples (a plugin reports it to its host), and in seconds.
    double latency_samples() const { return decimator_.group_delay(); }
    double latency_s() const { return latency_samples() / options_.host_rate_hz; }
    double internal_rate_hz() const { return factor_ * options_.host_rate_hz; }
    double host_rate_hz() const { return options_.host_rate_hz; }
    std::size_t mode_count() const { return case_.mode_count(); }
    int fret_count() const { return hand_.fret_count(); }
    int fret() const { return hand_.fret(); }  // the fret pressed; 0: none (open, or lifting)
    bool finger_on_string() const { return hand_.on(stepper_->string()); }
    // Where fret k stands (m from x = 0; 0: the nut), so that front ends pluck the sounding part.
    double fret_position_m(int fret) const;
    const Case& voice_case() const { return case_; }
    double length_m() const { return case_.string.length_m; }
    // Discrete energy H (J, the finger's included), energy dissipated (damping and the
    // finger's contact loss), the pressing force's work, and the energy the events put in since
    // set-up: H + dissipated - work = injected, to round-off.
    double energy() const { return stepper_->energy(); }
    double dissipated() const { return stepper_->dissipated(); }
    double work() const { return stepper_->work(); }
    double finger_loss() const { return stepper_->finger_loss(); }
    double injected() const { return guard_.injected(); }
    bool sounding() const;
    const EngineHealth& health() const { return health_; }
    // The stepper's counts (contact steps, steps flown...), for benchmarks and tests.
    const StepStatistics& statistics() const { return stepper_->statistics(); }

    static constexpr double kMuteScale = 300.0;

private:
    double clamp(double value, double low, double high);
    void render_host_sample();
    void apply_damping();
    void guard();
    void silence();
    double ledger() const { return energy() + dissipated() - work(); }
    void retire_lifted_finger();
    // Runs a change of state or plan, counting the energy it adds or removes as input.
    template <class Change>
    void change(Change&& f);

    EngineOptions options_;
    Case case_;
    int factor_ = 1;
    const char* rate_choice_ = "";
    std::unique_ptr<Plan> plan_;
    std::unique_ptr<Stepper> stepper_;
    std::optional<FreeFlight> flight_;
    std::size_t head_ = 0;
    Decimator decimator_;
    std::vector<std::vector<double>> pickup_;  // one probe: the mode shapes at the pickup
    std::vector<double> flight_u_;
    std::vector<double> grid_, dq_, dv_, zero_;
    std::vector<double> base_sigma_, sigma_;
    double damping_scale_ = 1.0;
    bool muted_ = false;
    EnergyGuard guard_;
    FretHand hand_;
    EngineHealth health_;
};

}  // namespace fretbuzz
