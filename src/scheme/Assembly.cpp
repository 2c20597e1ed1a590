#include "fretbuzz/scheme/Assembly.hpp"

namespace fretbuzz {

Assembly::Assembly(std::span<const OnBridge> strings, std::span<const BridgeModeSpec> bridge) {
    std::vector<double> stiffness;
    strings_.reserve(strings.size());
    for (const OnBridge& s : strings) {
        ends_.emplace_back(*s.plan, s.string);
        strings_.emplace_back(*s.plan, s.q0, s.v0, ends_.back().load_shapes());
        stiffness.push_back(ends_.back().stiffness());
        ends_.back().keep(strings_.back().modes());  // g . q'^0
    }
    bridge_.emplace(bridge, stiffness, strings.front().plan->dt());
    pulls_.assign(strings.size(), 0.0);
    now_.assign(strings.size(), 0.0);
    before_.assign(strings.size(), 0.0);
}

void Assembly::step_on_bridge() {
    // The first step is every string's free motion; the bridge stays at rest through it.
    const bool first = strings_.front().step_index() == 0;
    const std::size_t S = strings_.size();
    for (std::size_t s = 0; s < S; ++s) {
        now_[s] = bridge_->end(s);
        before_[s] = bridge_->end_before(s);
    }
    // The bridge first (the strings' pulls need only their free predictions), then each string
    // with the load of the end's w^n and w^{n-1}.
    if (!first) {
        for (std::size_t s = 0; s < S; ++s) pulls_[s] = ends_[s].pull(strings_[s], now_[s], before_[s]);
        bridge_->step(pulls_);
    }
    for (std::size_t s = 0; s < S; ++s) {
        ends_[s].step(strings_[s], now_[s], before_[s]);
        if (!first) ends_[s].correct_damping(bridge_->end(s) - before_[s]);
    }
}

void Assembly::perturb(std::size_t s, std::span<const double> displacement, std::span<const double> velocity) {
    strings_[s].perturb(displacement, velocity);
    if (bridge_) ends_[s].retake(strings_[s].modes());
}

void Assembly::silence(std::size_t s) {
    strings_[s].silence();
    if (bridge_) ends_[s].retake(strings_[s].modes());
}

void Assembly::damping_changed(std::size_t s) {
    strings_[s].restart();
    if (bridge_) ends_[s].reform(strings_[s]);
}

double Assembly::string_energy(std::size_t s) const {
    const VibratingString& string = strings_[s];
    if (!bridge_) return string.energy();
    return string.energy() + ends_[s].energy(string.modes(), string.modal_energy(), bridge_->end(s), bridge_->end_before(s));
}

double Assembly::energy() const {
    double e = bridge_ ? bridge_->energy() : 0.0;
    for (std::size_t s = 0; s < strings_.size(); ++s) e += string_energy(s);
    return e;
}

double Assembly::dissipated() const {
    double e = bridge_ ? bridge_->dissipated() : 0.0;
    for (std::size_t s = 0; s < strings_.size(); ++s) {
        e += strings_[s].dissipated();
        if (bridge_) e += ends_[s].damping_correction();
    }
    return e;
}

double Assembly::work() const {
    double e = 0.0;
    for (const VibratingString& s : strings_) e += s.work();  // driven loads' work is not counted
    return e;
}

}  // namespace fretbuzz
