#include "fretbuzz/realtime/Engine.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/StoppedString.hpp"
#include "fretbuzz/scheme/Kernels.hpp"
#include "fretbuzz/scheme/TimeProfile.hpp"

#if defined(__x86_64__) || defined(__SSE2__)
#include <xmmintrin.h>
#define FRETBUZZ_HAS_MXCSR 1
#endif

namespace fretbuzz {

namespace {
// Modes are kept below this fraction of the internal rate: under the Nyquist frequency with
// a margin, so no mode aliases under contact (see SamplingCheck).
constexpr double kBandEdge = 0.45;
// Free flight steps the modes up to this fraction of the host rate (the decimator removes
// the rest), and at least this many (sharp checks of sleeping points).
constexpr double kFlightBand = 0.6;
// A flight over one host sample costs a few passes over every mode (the energy after it, the
// speed bound and its tail, the jump of the modes it leaves out) and saves M - 1 steps of the
// modes it leaves out: at M = 2 the passes cost more than the steps saved; from M = 4 on it
// pays (fretbuzz_bench_realtime; the figures are in docs/performance.md).
constexpr int kMinimumFlightFactor = 4;
// Relative allowance on the energy guard: far above the round-off of the balance.
constexpr double kGuardTolerance = 1e-6;
// Below this fraction of the largest energy struck in, the voice is silent and not stepped.
constexpr double kSilentFraction = 1e-14;
// A mute damps even a lossless string.
constexpr double kMuteFloor = 30.0;  // 1/s

// Flushes denormals to zero (and treats denormal inputs as zero) while it lives: a decaying
// string would otherwise slow to a crawl as its modes sink below 1e-308.
class FlushDenormals {
public:
#ifdef FRETBUZZ_HAS_MXCSR
    FlushDenormals() : saved_(_mm_getcsr()) { _mm_setcsr(saved_ | 0x8040u); }
    ~FlushDenormals() { _mm_setcsr(saved_); }

private:
    unsigned saved_;
#endif
};

struct RateChoice {
    int factor;
    std::size_t modes;
    const char* reason;
};

// Why M is what it is, as `play` prints it.
constexpr const char* kRateAsked = "set by the oversampling option";
constexpr const char* kRateEveryMode =
    "the smallest that keeps every mode below 0.45 x the internal rate (a lower one drops modes the contact needs)";
constexpr const char* kRateCapped =
    "capped by max_oversampling: the modes above 0.45 x the internal rate are dropped";

// The default keeps every mode of the case: the contact needs them. Measured by
// fretbuzz_rate_accuracy (first 0.5 s after a strike, against the same voice at M = 8, which
// M = 16 confirms to 0.3 dB): a rate that drops modes changes the tanpura by 2.3 dB
// (log-spectral distance over 1/6-octave bands) and its centroid by 6 % at M = 2, 5.9 dB and
// 23 % at M = 4, the sitar by 3.2 dB / 6 % and 5.5 dB / 8 %; not monotonically in M (the
// point contact's stiffness depends on where the modal series is cut). With the same modes,
// M = 2 and M = 8 differ by 1.4 dB: the modes dropped, more than the step, are the error.
RateChoice choose_rate(const Case& c, const EngineOptions& o) {
    const std::size_t available = o.max_modes > 0 ? std::min(o.max_modes, c.mode_count()) : c.mode_count();
    const auto modes_below = [&](double edge_hz) {
        std::size_t n = 0;
        while (n < available && c.modes.frequency_hz[n] < edge_hz) ++n;
        return n;
    };
    if (o.oversampling > 0) return {o.oversampling, modes_below(kBandEdge * o.oversampling * o.host_rate_hz), kRateAsked};
    for (int m = 1; m <= o.max_oversampling; ++m)
        if (modes_below(kBandEdge * m * o.host_rate_hz) == available) return {m, available, kRateEveryMode};
    return {o.max_oversampling, modes_below(kBandEdge * o.max_oversampling * o.host_rate_hz), kRateCapped};
}

void check_options(const EngineOptions& o) {
    const auto in = [](const char* name, double v, double low, double high, const char* range) {
        if (!(v >= low && v <= high)) throw InputError(out_of_range_message(name, v, range));
    };
    in("host rate (Hz)", o.host_rate_hz, 8000.0, 768000.0, "[8000, 768000]");
    in("oversampling", o.oversampling, 0, 64, "0 (automatic) to 64");
    in("max oversampling", o.max_oversampling, 1, 64, "1 to 64");
    in("taps per phase", o.taps_per_phase, 4, 256, "4 to 256");
    in("gain per metre", o.gain_per_m, 0.0, 1e9, "[0, 1e9]");
}

}  // namespace

bool sine_transform_allocates(std::size_t n) {
    std::size_t m = n + 1;
    for (std::size_t p = 2; p <= 31; ++p)
        while (m % p == 0) m /= p;
    return m != 1;
}

Engine::Engine(const Case& c, const EngineOptions& options) : options_(options), decimator_(1) {
    check_options(options);
    const RateChoice rate = choose_rate(c, options);
    if (rate.modes == 0)
        throw InputError(out_of_range_message("oversampling", rate.factor,
                                              "high enough that the first mode lies below 0.45 x the internal rate"));
    factor_ = rate.factor;
    rate_choice_ = rate.reason;
    case_ = rate.modes == c.mode_count() ? c : stopped_string(c, 0.0, rate.modes);
    case_.run.sample_rate_hz = internal_rate_hz();
    add_finger_room();
    PlanOptions plan_options;
    if (sine_transform_allocates(case_.mode_count()))  // rows of S only: FFTW's transform would allocate
        plan_options.transform_threshold = std::numeric_limits<std::size_t>::max();
    plan_ = std::make_unique<Plan>(case_, 1.0 / internal_rate_hz(), plan_options);
    plan_->prepare_rows();
    // The rows of every pad the finger may take (a row is built the first time it is used).
    std::vector<std::size_t> pad;
    for (const auto& [centre, width] : fret_pads_) {
        pad_points(centre, width, case_.grid_step(), case_.mode_count(), pad);
        for (std::size_t i : pad) plan_->basis().row(i);
    }
    const auto start = [&](const std::vector<double>& v) {
        return options.start_from_case ? plan_->oriented(v) : std::vector<double>(v.size(), 0.0);
    };
    stepper_ = std::make_unique<Stepper>(*plan_, start(case_.initial_displacement), start(case_.initial_velocity));
    stepper_->step();  // the first step is special (exact free motion); from here on, the scheme
    if (finger_ != kNoFinger) stepper_->lift_finger(finger_);  // off the string until a note
    injected_ = ledger();
    peak_ = injected_;

    const std::size_t n = case_.mode_count();
    pickup_.assign(1, std::vector<double>(n, 0.0));
    const double pickup = options.pickup_m < 0.0 ? case_.observation_points_m.front() : options.pickup_m;
    if (!(pickup > 0.0 && pickup < length_m()))
        throw InputError(out_of_range_message("pickup position (m)", pickup, "(0, L), L = " + std::to_string(length_m())));
    set_pickup(pickup);
    while (head_ < n && case_.modes.frequency_hz[head_] < kFlightBand * options.host_rate_hz) ++head_;
    head_ = std::max(head_, std::min(kMinimumFlightModes, n));
    if (options.free_flight && factor_ >= kMinimumFlightFactor && head_ < n)
        flight_.emplace(plan_->propagator(), factor_, head_);
    flight_u_.assign(static_cast<std::size_t>(factor_), 0.0);
    decimator_ = Decimator(factor_, options.taps_per_phase);
    grid_.assign(n, 0.0);
    dq_.assign(n, 0.0);
    dv_.assign(n, 0.0);
    zero_.assign(n, 0.0);
    base_sigma_ = case_.modes.sigma_per_s;
    sigma_ = base_sigma_;
}

void Engine::add_finger_room() {
    // One finger, the default of `fret = k`: its pad for every fret is known now, and the
    // stepper is given the finger (lifted right after the first step) so that its room exists
    // before any note. Its pad is as wide as any fret's, so moving it allocates nothing.
    if (case_.fret_positions_m.empty()) return;
    // Exact frets keep their exact positions beside the finger wherever it is placed (the Plan
    // solves it with them), so the frets stay where the case puts them whatever the mode count.
    const std::size_t frets = case_.fret_positions_m.size();
    FingerSpec spare = case_.fret_finger(1, "the engine's finger: fret");
    for (std::size_t k = 1; k <= frets; ++k) {
        const FingerSpec f = case_.fret_finger(k, "fret");
        fret_pads_.push_back({f.position_m, f.width_m});
        spare.width_m = std::max(spare.width_m, f.width_m);
    }
    // The pressing force of `fret = k`: a ramp from 0 to its last value.
    finger_force_ = spare.force_profile.back()[1];
    finger_ramp_steps_ = std::max(1L, std::lround(spare.force_profile.back()[0] * internal_rate_hz()));
    spare.force_profile.clear();
    spare.default_force = false;
    finger_ = case_.fingers.size();
    case_.fingers.push_back(std::move(spare));
}

double Engine::fret_position_m(int fret) const {
    if (fret <= 0 || fret > fret_count()) return 0.0;
    return case_.fret_positions_m[static_cast<std::size_t>(fret - 1)];
}

bool Engine::finger_down(int fret) {
    if (finger_ == kNoFinger) {
        ++health_.clamped;
        return false;
    }
    const int k = static_cast<int>(clamp(fret, 0.0, fret_count()));
    if (k == 0) {
        finger_up();
        return true;
    }
    const double centre = fret_pads_[static_cast<std::size_t>(k - 1)][0];
    const double width = fret_pads_[static_cast<std::size_t>(k - 1)][1];
    bool placed = false;
    change([&] {
        placed = stepper_->place_finger(finger_, centre, width);
        if (placed) stepper_->press_finger(finger_, finger_force_, finger_ramp_steps_);
    });
    fret_ = placed ? k : 0;
    lifting_ = false;
    return placed;
}

void Engine::finger_up() {
    if (finger_ == kNoFinger || !stepper_->finger_on(finger_) || lifting_) return;
    stepper_->press_finger(finger_, 0.0, finger_ramp_steps_);  // changes no energy now
    lifting_ = true;
    lifted_at_ = stepper_->step_index() + finger_ramp_steps_;
    fret_ = 0;
}

void Engine::retire_lifted_finger() {
    // Once its force is gone and it has left the string, the finger stops being stepped: the
    // open string may fly again. Its kinetic energy leaves with it (counted).
    if (!lifting_ || stepper_->step_index() < lifted_at_) return;
    const Finger& finger = stepper_->fingers()[finger_];
    if (finger.acted() || finger.contact_energy() != 0.0) return;
    lifting_ = false;
    change([&] { stepper_->lift_finger(finger_); });
}

double Engine::clamp(double value, double low, double high) {
    if (std::isnan(value)) {
        ++health_.clamped;
        return low;
    }
    if (value < low || value > high) ++health_.clamped;
    return std::clamp(value, low, high);
}

bool Engine::sounding() const { return energy() > kSilentFraction * peak_; }

void Engine::process(std::span<float> out) {
    const FlushDenormals ftz;
    if (!sounding()) {
        // Nothing to hear: the string is not stepped (its time stands still), the filter drains.
        for (float& y : out) {
            for (int k = 0; k < factor_; ++k) decimator_.push(0.0);
            y = static_cast<float>(options_.gain_per_m * decimator_.output());
        }
        return;
    }
    try {
        for (float& y : out) {
            render_host_sample();
            const double value = options_.gain_per_m * decimator_.output();
            y = std::isfinite(value) ? static_cast<float>(value) : 0.0f;
        }
    } catch (const SolverError&) {
        ++health_.solver_failures;
        for (float& y : out) y = 0.0f;
        silence();
        return;
    }
    retire_lifted_finger();
    guard();
}

void Engine::render_internal(std::span<double> out) {
    const FlushDenormals ftz;
    for (double& u : out) {
        stepper_->step();
        u = stepper_->observation();
    }
}

void Engine::render_host_sample() {
    int k = 0;
    if (flight_) {
        k = static_cast<int>(stepper_->free_flight(*flight_, head_, pickup_, flight_u_, nullptr));
        for (int m = 0; m < k; ++m) decimator_.push(flight_u_[static_cast<std::size_t>(m)]);
    }
    for (; k < factor_; ++k) {
        stepper_->step();
        decimator_.push(stepper_->observation());  // formed by the step's own pass over the modes
    }
}

template <class Change>
void Engine::change(Change&& f) {
    const double before = ledger();
    f();
    injected_ += ledger() - before;
    guard();
}

void Engine::guard() {
    const double total = ledger();
    const double scale = std::max({std::abs(injected_), peak_, std::abs(work())});
    if (std::isfinite(total) && total <= injected_ + kGuardTolerance * scale) return;
    ++health_.resets;
    silence();
}

void Engine::stop() { silence(); }

void Engine::silence() {
    if (finger_ != kNoFinger) stepper_->lift_finger(finger_);
    fret_ = 0;
    lifting_ = false;
    stepper_->silence();
    decimator_.reset();
    injected_ = ledger();
}

void Engine::strike(const Strike& s) {
    const double dx = case_.grid_step();
    const double width = clamp(s.width_m, 2.0 * dx, 0.5 * length_m());
    const double position = clamp(s.position_m, 0.5 * width, length_m() - 0.5 * width);
    const double limit = s.displacement ? 0.02 : 20.0;  // m or m/s: far beyond any real pluck
    const double strength = clamp(s.strength, -limit, limit);
    // The bump's modal coordinates, dx S^T u, summed over its few grid points by rows of S.
    std::vector<double>& target = s.displacement ? dq_ : dv_;
    const std::size_t n = grid_.size();
    const auto first = static_cast<std::size_t>(std::max(0.0, std::floor((position - 0.5 * width) / dx)));
    for (std::size_t i = first > 0 ? first - 1 : 0; i < n && case_.grid_point(i) < position + 0.5 * width; ++i) {
        const double r = std::abs(case_.grid_point(i) - position) / (0.5 * width);
        if (r >= 1.0) continue;
        const double u = plan_->oriented(strength) * 0.5 * (1.0 + std::cos(std::numbers::pi * r));
        kernels::axpy(dx * u, plan_->basis().row(i, grid_).data(), target.data(), n);
    }
    change([&] { stepper_->perturb(s.displacement ? dq_ : zero_, s.displacement ? zero_ : dv_); });
    peak_ = std::max(peak_, energy());
    std::fill(target.begin(), target.end(), 0.0);
}

void Engine::set_damping_scale(double scale) {
    damping_scale_ = clamp(scale, 0.0, 1000.0);
    apply_damping();
}

void Engine::mute(bool on) {
    if (on == muted_) return;
    muted_ = on;
    apply_damping();
}

void Engine::apply_damping() {
    for (std::size_t j = 0; j < sigma_.size(); ++j)
        sigma_[j] = muted_ ? base_sigma_[j] * damping_scale_ * kMuteScale + kMuteFloor : base_sigma_[j] * damping_scale_;
    change([&] {
        plan_->set_damping(sigma_);
        if (flight_) flight_->update(plan_->propagator());
        stepper_->restart();
    });
}

void Engine::set_contact_law(double stiffness, double exponent) {
    const double k = clamp(stiffness, 1.0, 1e16);
    const double alpha = clamp(exponent, 1.0, 3.0);
    change([&] {
        plan_->set_contact_law(k, alpha);
        stepper_->restart();
    });
}

void Engine::set_obstacle_offset(double offset_m) {
    const double offset = clamp(offset_m, -5e-3, 1e-3);
    change([&] {
        plan_->set_obstacle_offset(offset);
        stepper_->restart();
    });
}

void Engine::set_pickup(double x_m) {
    const double dx = case_.grid_step();
    const double x = clamp(x_m, dx, length_m() - dx);
    plan_->basis().mode_shapes_at(x, pickup_.front());
    plan_->orient(pickup_.front());
    stepper_->observe(pickup_.front());
}

}  // namespace fretbuzz
