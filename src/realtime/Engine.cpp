#include "fretbuzz/realtime/Engine.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/realtime/InternalRate.hpp"
#include "fretbuzz/numerics/Kernels.hpp"
#include "fretbuzz/numerics/TimeProfile.hpp"


namespace fretbuzz {

namespace {
// Free flight steps the modes up to this fraction of the host rate (the decimator removes
// the rest), and at least this many (sharp checks of sleeping points).
constexpr double kFlightBand = 0.6;
// A flight over one host sample costs a few passes over every mode (the energy after it, the
// speed bound and its tail, the jump of the modes it leaves out) and saves M - 1 steps of the
// modes it leaves out: at M = 2 the passes cost more than the steps saved; from M = 4 on it
// pays (fretbuzz_bench_realtime; the figures are in docs/performance.md).
constexpr int kMinimumFlightFactor = 4;
// A mute damps even a lossless string.
constexpr double kMuteFloor = 30.0;  // 1/s
}  // namespace

bool sine_transform_allocates(std::size_t n) {
    std::size_t m = n + 1;
    for (std::size_t p = 2; p <= 31; ++p)
        while (m % p == 0) m /= p;
    return m != 1;
}

Engine::Engine(const Case& c, const EngineOptions& options) : options_(options), decimator_(1) {
    check_engine_options(options);
    const RateChoice rate = choose_rate(c, options);
    factor_ = rate.factor;
    rate_choice_ = rate.reason;
    case_ = case_at_internal_rate(c, rate.modes, factor_, internal_rate_hz());
    hand_.add_to(case_, internal_rate_hz());
    plan_ = std::make_unique<Plan>(case_, 1.0 / internal_rate_hz(), realtime_plan_options(case_.mode_count()));
    plan_->prepare_rows();
    hand_.prepare_rows(*plan_, case_);
    const auto start = [&](const std::vector<double>& v) {
        return options.start_from_case ? plan_->oriented(v) : std::vector<double>(v.size(), 0.0);
    };
    stepper_ = std::make_unique<Stepper>(*plan_, start(case_.initial_displacement), start(case_.initial_velocity));
    stepper_->step();  // the first step is special (exact free motion); from here on, the scheme
    hand_.take_off(stepper_->string());  // off the string until a note
    guard_.start(ledger());

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

double Engine::fret_position_m(int fret) const {
    if (fret <= 0 || fret > fret_count()) return 0.0;
    return case_.fret_positions_m[static_cast<std::size_t>(fret - 1)];
}

bool Engine::finger_down(int fret) {
    if (!hand_.present()) {
        ++health_.clamped;
        return false;
    }
    const int k = static_cast<int>(clamp(fret, 0.0, fret_count()));
    if (k == 0) {
        finger_up();
        return true;
    }
    bool placed = false;
    change([&] { placed = hand_.down(stepper_->string(), k); });
    return placed;
}

void Engine::finger_up() { hand_.up(stepper_->string()); }

void Engine::retire_lifted_finger() {
    // Once its force is gone and it has left the string, the finger stops being stepped: the
    // open string may fly again. Its kinetic energy leaves with it (counted).
    if (hand_.ready_to_retire(stepper_->string())) change([&] { hand_.take_off(stepper_->string()); });
}

double clamp_counted(double value, double low, double high, long& count) {
    if (std::isnan(value)) {
        ++count;
        return low;
    }
    if (value < low || value > high) ++count;
    return std::clamp(value, low, high);
}

double Engine::clamp(double value, double low, double high) { return clamp_counted(value, low, high, health_.clamped); }

bool Engine::sounding() const { return guard_.sounding(energy()); }

void Engine::process(std::span<float> out) {
    const bool stepped = sounding();
    const bool ok = render_block(out, decimator_, factor_, options_.gain_per_m, stepped,
                                 [this](Decimator&) { render_host_sample(); });
    if (!stepped) return;
    if (!ok) {
        ++health_.solver_failures;
        silence();
        return;
    }
    retire_lifted_finger();
    guard();
}

void Engine::render_internal(std::span<double> out) {
    const SubnormalFlush flushed;
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
    guard_.change([this] { return ledger(); }, f);
    guard();
}

void Engine::guard() {
    if (guard_.holds(ledger(), work())) return;
    ++health_.resets;
    silence();
}

void Engine::stop() { silence(); }

void Engine::silence() {
    hand_.take_off(stepper_->string());
    stepper_->silence();
    decimator_.reset();
    guard_.restart(ledger());
}

void add_strike(const Strike& s, const Case& c, const Plan& plan, std::vector<double>& row,
                std::vector<double>& target, long& clamped) {
    const double dx = c.grid_step();
    const double length = c.string.length_m;
    const double width = clamp_counted(s.width_m, 2.0 * dx, 0.5 * length, clamped);
    const double position = clamp_counted(s.position_m, 0.5 * width, length - 0.5 * width, clamped);
    const double limit = s.displacement ? 0.02 : 20.0;  // m or m/s: far beyond any real pluck
    const double strength = clamp_counted(s.strength, -limit, limit, clamped);
    // The bump's modal coordinates, dx S^T u, summed over its few grid points by rows of S.
    const std::size_t n = c.mode_count();
    const auto first = static_cast<std::size_t>(std::max(0.0, std::floor((position - 0.5 * width) / dx)));
    for (std::size_t i = first > 0 ? first - 1 : 0; i < n && c.grid_point(i) < position + 0.5 * width; ++i) {
        const double r = std::abs(c.grid_point(i) - position) / (0.5 * width);
        if (r >= 1.0) continue;
        const double u = plan.oriented(strength) * 0.5 * (1.0 + std::cos(std::numbers::pi * r));
        kernels::axpy(dx * u, plan.basis().row(i, row).data(), target.data(), n);
    }
}

void Engine::strike(const Strike& s) {
    std::vector<double>& target = s.displacement ? dq_ : dv_;
    add_strike(s, case_, *plan_, grid_, target, health_.clamped);
    change([&] { stepper_->perturb(s.displacement ? dq_ : zero_, s.displacement ? zero_ : dv_); });
    guard_.struck(energy());
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

void voice_damping(std::span<const double> base, double scale, bool muted, std::span<double> sigma) {
    for (std::size_t j = 0; j < sigma.size(); ++j)
        sigma[j] = muted ? base[j] * scale * Engine::kMuteScale + kMuteFloor : base[j] * scale;
}

void Engine::apply_damping() {
    voice_damping(base_sigma_, damping_scale_, muted_, sigma_);
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
