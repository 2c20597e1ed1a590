#pragma once
// A real-time voice of strings on one bridge (a StringsCase: a sitar's main string with its
// taraf strings, a guitar's six strings), rendered in blocks at the host rate while events
// arrive between blocks: a strike of string s, a finger down behind a fret of a fretted string
// or lifted, a stop.
//
// It runs the offline coupling itself (Plan per string, Assembly, Bridge: no second physics)
// at one internal rate M x the host rate, M chosen as Engine chooses it for the played string
// (the main string, which buzzes: InternalRate); every string keeps its modes below 0.45 x the
// internal rate, and a string that touches nothing may be cut further (max_free_modes). The
// strings share one time step and the bridge loads every string at every step, so nothing
// flies free: every mode of every string is stepped at every internal step.
//
// What is heard: by default the sum of the strings' pickup displacements (each string's first
// observation point), decimated by M as Engine's signal is: each string is heard as itself,
// the taraf's sympathetic ringing included, at the level of the one-string voice. The bridge's
// velocity is the other choice (output = bridge): the drive of the body, but through the case's
// few bridge modes only (a mass-like, dull response above them), not a radiated sound.
//
// Damping and mute as Engine's (voice_damping), per string: the string's plan takes the new
// damping and the assembly forms its bridge end's loads again (Assembly::damping_changed); the
// energy the change moves is counted as input, as every event's.
//
// The audio path (process and every event) allocates nothing and takes no lock. The guard is
// Engine's: the assembly's H + dissipated - W (strings, their ends' links, the bridge, the
// fingers) may not exceed the energy the events put in. A strike or a silence goes through the
// assembly (Assembly::perturb, silence), which takes the string's bridge end anew, so the
// balance stays exact across it.
#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/realtime/Decimator.hpp"
#include "fretbuzz/realtime/Engine.hpp"
#include "fretbuzz/realtime/EnergyGuard.hpp"
#include "fretbuzz/realtime/FretHand.hpp"
#include "fretbuzz/scheme/Assembly.hpp"
#include "fretbuzz/scheme/Plan.hpp"

namespace fretbuzz {

struct BridgeEngineOptions {
    // Host rate, oversampling (chosen for the played string), taps, gain; start_from_case
    // starts every string from its case (else all at rest, with the case's gestures, pluckers
    // and fingers left out: the voice is played by events). pickup_m and free_flight are not used.
    EngineOptions engine;
    std::size_t played = 0;          // the string whose modes choose M (the main string)
    std::size_t max_free_modes = 0;  // per string with no obstacle: at most this many modes (0: all)
    enum class Output { pickups, bridge } output = Output::pickups;
    double bridge_gain_per_m_s = 10.0;  // output sample per m/s of the bridge (output = bridge)
};

class BridgeEngine {
public:
    // The costly set-up: plans every string at the internal rate and steps the assembly once.
    // InputError for bad options (named, with their range).
    BridgeEngine(const StringsCase& sc, const BridgeEngineOptions& options = {});
    BridgeEngine(const BridgeEngine&) = delete;
    BridgeEngine& operator=(const BridgeEngine&) = delete;

    // Renders out.size() host samples. Allocates nothing.
    void process(std::span<float> out);
    // Renders out.size() internal steps of the undecimated signal (m, or m/s for the bridge).
    void render_internal(std::span<double> out);

    // Events, between blocks; none allocates. Values out of range are clamped (health().clamped).
    void strike(std::size_t string, const Strike& s);
    // Finger behind fret k of a fretted string (as Engine's); k = 0 lifts it. False on a
    // string with no frets.
    bool finger_down(std::size_t string, int fret);
    void finger_up(std::size_t string);
    // Every string at rest at once (the bridge rings out its own motion).
    void stop();
    // Every mode's damping times `scale` (in [0, 1000]) on every string; a muted string's
    // times Engine::kMuteScale plus a floor (a hand laid on it), until unmuted.
    void set_damping_scale(double scale);
    void mute(std::size_t string, bool on);
    bool muted(std::size_t string) const { return string < muted_.size() && muted_[string] != 0; }

    std::size_t string_count() const { return cases_.size(); }
    const std::string& string_name(std::size_t s) const { return names_[s]; }
    const Case& string_case(std::size_t s) const { return cases_[s]; }
    double length_m(std::size_t s) const { return cases_[s].string.length_m; }
    int fret_count(std::size_t s) const { return hands_[s].fret_count(); }
    int fret(std::size_t s) const { return hands_[s].fret(); }
    bool finger_on_string(std::size_t s) const { return hands_[s].on(assembly_->string(s)); }
    double fret_position_m(std::size_t s, int fret) const;
    std::size_t mode_count(std::size_t s) const { return cases_[s].mode_count(); }
    int oversampling() const { return factor_; }
    const char* rate_choice() const { return rate_choice_; }
    double internal_rate_hz() const { return factor_ * options_.engine.host_rate_hz; }
    double host_rate_hz() const { return options_.engine.host_rate_hz; }
    double latency_samples() const { return decimator_.group_delay(); }
    const Assembly& assembly() const { return *assembly_; }

    // The assembly's balance terms and the energy put in: H + dissipated - work = injected.
    double energy() const { return assembly_->energy(); }
    double dissipated() const { return assembly_->dissipated(); }
    double work() const { return assembly_->work(); }
    double injected() const { return guard_.injected(); }
    bool sounding() const { return guard_.sounding(energy()); }
    const EngineHealth& health() const { return health_; }

private:
    double ledger() const { return energy() + dissipated() - work(); }
    double sample() const;
    void step_sample(Decimator& decimator);
    template <class Change>
    void change(Change&& f);
    void guard();
    void silence();
    bool valid(std::size_t s);
    void apply_damping(std::size_t s);

    BridgeEngineOptions options_;
    int factor_ = 1;
    const char* rate_choice_ = "";
    std::vector<std::string> names_;
    std::vector<Case> cases_;
    std::vector<std::unique_ptr<Plan>> plans_;
    std::optional<Assembly> assembly_;
    std::vector<FretHand> hands_;  // each string's fretting hand (strings with frets)
    std::vector<std::vector<double>> pickups_;  // per string: the mode shapes at its pickup
    std::vector<std::vector<double>> row_, push_, zero_;  // per string: scratch for strikes
    std::vector<std::vector<double>> base_sigma_, sigma_;  // per string: the case's damping, and now
    std::vector<char> muted_;
    double damping_scale_ = 1.0;
    Decimator decimator_;
    EnergyGuard guard_;
    EngineHealth health_;
};

}  // namespace fretbuzz
