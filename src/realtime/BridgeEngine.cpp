#include "fretbuzz/realtime/BridgeEngine.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/realtime/InternalRate.hpp"

namespace fretbuzz {

namespace {

void check_options(const StringsCase& sc, const BridgeEngineOptions& o) {
    check_engine_options(o.engine);
    if (o.played >= sc.strings.size())
        throw InputError(out_of_range_message("played string", static_cast<double>(o.played),
                                              "0 to " + std::to_string(sc.strings.size() - 1) + ", the strings of " + sc.name));
    if (!(o.bridge_gain_per_m_s >= 0.0 && o.bridge_gain_per_m_s <= 1e9))
        throw InputError(out_of_range_message("bridge gain (per m/s)", o.bridge_gain_per_m_s, "[0, 1e9]"));
}

}  // namespace

BridgeEngine::BridgeEngine(const StringsCase& sc, const BridgeEngineOptions& options)
    : options_(options), decimator_(1) {
    check_options(sc, options);
    const RateChoice rate = choose_rate(sc.strings[options.played], options.engine);
    factor_ = rate.factor;
    rate_choice_ = rate.reason;
    const double fs = internal_rate_hz();
    const std::size_t S = sc.strings.size();
    hands_.resize(S);
    for (std::size_t s = 0; s < S; ++s) {
        const Case& c = sc.strings[s];
        std::size_t available = s == options.played ? rate.modes : c.mode_count();
        if (!c.has_obstacle() && options.max_free_modes > 0) available = std::min(available, options.max_free_modes);
        Case voice = case_at_internal_rate(c, modes_below(c, available, kBandEdge * fs), factor_, fs);
        if (!options.engine.start_from_case) {  // played by events only
            voice.forces.clear();
            voice.plucks.clear();
            voice.fingers.clear();
        }
        // (a string started from its case with fingers of its own is played by them)
        if (voice.fingers.empty()) hands_[s].add_to(voice, fs);
        plans_.push_back(std::make_unique<Plan>(voice, 1.0 / fs, realtime_plan_options(voice.mode_count())));
        plans_.back()->prepare_rows();
        hands_[s].prepare_rows(*plans_.back(), voice);
        names_.push_back(s < sc.string_names.size() ? sc.string_names[s] : "string " + std::to_string(s + 1));
        cases_.push_back(std::move(voice));
    }
    // The initial state as the offline run takes it (StringsRun), or at rest.
    std::vector<std::vector<double>> q0, v0;
    std::vector<Assembly::OnBridge> on_bridge;
    for (std::size_t s = 0; s < S; ++s) {
        const Case& c = cases_[s];
        const bool from_case = options.engine.start_from_case;
        q0.push_back(from_case ? c.initial_displacement : std::vector<double>(c.mode_count(), 0.0));
        v0.push_back(from_case ? c.initial_velocity : std::vector<double>(c.mode_count(), 0.0));
    }
    for (std::size_t s = 0; s < S; ++s) on_bridge.push_back({plans_[s].get(), cases_[s].string, q0[s], v0[s]});
    assembly_.emplace(on_bridge, sc.bridge);
    assembly_->step();  // the first step is every string's free motion
    for (std::size_t s = 0; s < S; ++s) hands_[s].take_off(assembly_->string(s));

    for (std::size_t s = 0; s < S; ++s) {
        const Case& c = cases_[s];
        const double x = c.observation_points_m.empty() ? 0.9 * c.string.length_m : c.observation_points_m.front();
        pickups_.push_back(plans_[s]->basis().mode_shapes_at(x));
        plans_[s]->orient(pickups_.back());
        assembly_->string(s).pickups().observe(pickups_.back().data(), assembly_->string(s).modes());
        base_sigma_.push_back(c.modes.sigma_per_s);
        sigma_.push_back(c.modes.sigma_per_s);
        row_.emplace_back(c.mode_count(), 0.0);
        push_.emplace_back(c.mode_count(), 0.0);
        zero_.emplace_back(c.mode_count(), 0.0);
    }
    muted_.assign(S, 0);
    guard_.start(ledger());
    decimator_ = Decimator(factor_, options.engine.taps_per_phase);
}

double BridgeEngine::fret_position_m(std::size_t s, int fret) const {
    if (s >= cases_.size() || fret <= 0 || fret > fret_count(s)) return 0.0;
    return cases_[s].fret_positions_m[static_cast<std::size_t>(fret - 1)];
}

double BridgeEngine::sample() const {
    if (options_.output == BridgeEngineOptions::Output::bridge) return assembly_->bridge()->velocity();
    double u = 0.0;
    for (std::size_t s = 0; s < cases_.size(); ++s) {
        const VibratingString& string = assembly_->string(s);
        u += string.pickups().observation(string.plan().options().fused_step, string.modes());
    }
    return u;
}

void BridgeEngine::step_sample(Decimator& decimator) {
    for (int k = 0; k < factor_; ++k) {
        assembly_->step();
        decimator.push(sample());
    }
}

void BridgeEngine::process(std::span<float> out) {
    const bool stepped = sounding();
    const double gain =
        options_.output == BridgeEngineOptions::Output::bridge ? options_.bridge_gain_per_m_s : options_.engine.gain_per_m;
    const bool ok = render_block(out, decimator_, factor_, gain, stepped, [this](Decimator& d) { step_sample(d); });
    if (!stepped) return;
    if (!ok) {
        ++health_.solver_failures;
        silence();
        return;
    }
    for (std::size_t s = 0; s < hands_.size(); ++s) {
        FretHand& hand = hands_[s];
        if (hand.ready_to_retire(assembly_->string(s))) change([&] { hand.take_off(assembly_->string(s)); });
    }
    guard();
}

void BridgeEngine::render_internal(std::span<double> out) {
    const SubnormalFlush flushed;
    for (double& u : out) {
        assembly_->step();
        u = sample();
    }
}

template <class Change>
void BridgeEngine::change(Change&& f) {
    guard_.change([this] { return ledger(); }, f);
    guard();
}

void BridgeEngine::guard() {
    if (guard_.holds(ledger(), work())) return;
    ++health_.resets;
    silence();
}

void BridgeEngine::silence() {
    for (std::size_t s = 0; s < hands_.size(); ++s) {
        hands_[s].take_off(assembly_->string(s));
        assembly_->silence(s);
    }
    decimator_.reset();
    guard_.restart(ledger());
}

void BridgeEngine::stop() { silence(); }

void BridgeEngine::set_damping_scale(double scale) {
    damping_scale_ = clamp_counted(scale, 0.0, 1000.0, health_.clamped);
    for (std::size_t s = 0; s < cases_.size(); ++s) apply_damping(s);
}

void BridgeEngine::mute(std::size_t string, bool on) {
    if (!valid(string) || (muted_[string] != 0) == on) return;
    muted_[string] = on ? 1 : 0;
    apply_damping(string);
}

void BridgeEngine::apply_damping(std::size_t s) {
    voice_damping(base_sigma_[s], damping_scale_, muted_[s] != 0, sigma_[s]);
    change([&] {
        plans_[s]->set_damping(sigma_[s]);
        assembly_->damping_changed(s);
    });
}

bool BridgeEngine::valid(std::size_t s) {
    if (s < cases_.size()) return true;
    ++health_.clamped;
    return false;
}

void BridgeEngine::strike(std::size_t string, const Strike& s) {
    if (!valid(string)) return;
    std::vector<double>& push = push_[string];
    add_strike(s, cases_[string], *plans_[string], row_[string], push, health_.clamped);
    const std::vector<double>& zero = zero_[string];
    change([&] { assembly_->perturb(string, s.displacement ? push : zero, s.displacement ? zero : push); });
    guard_.struck(energy());
    std::fill(push.begin(), push.end(), 0.0);
}

bool BridgeEngine::finger_down(std::size_t string, int fret) {
    if (!valid(string)) return false;
    FretHand& hand = hands_[string];
    if (!hand.present()) {
        ++health_.clamped;
        return false;
    }
    const int k = static_cast<int>(clamp_counted(fret, 0.0, hand.fret_count(), health_.clamped));
    if (k == 0) {
        finger_up(string);
        return true;
    }
    bool placed = false;
    change([&] { placed = hand.down(assembly_->string(string), k); });
    return placed;
}

void BridgeEngine::finger_up(std::size_t string) {
    if (valid(string)) hands_[string].up(assembly_->string(string));
}

}  // namespace fretbuzz
