#pragma once
// Strings stepped together, and what couples them. Each string (VibratingString) owns its plan's
// state, contacts and ledger; the assembly steps them in the same time step and sums their
// balances. One string alone is what Stepper fronts. Strings on a bridge (Bridge) each rest on
// it by their end (BridgeEnd): the bridge's motion loads each string as a force known before the
// step (so every string's contacts are solved on their own, as ever), then the bridge takes the
// strings' pulls in one small linear solve. One balance: the strings' terms, their ends' link
// energy, the bridge's energy and damping.
#include <cstddef>
#include <optional>
#include <span>
#include <vector>

#include "fretbuzz/scheme/Bridge.hpp"
#include "fretbuzz/scheme/BridgeEnd.hpp"
#include "fretbuzz/scheme/VibratingString.hpp"

namespace fretbuzz {

class Assembly {
public:
    // One string on `plan`, at n = 0 from modal displacement q0 and velocity v0.
    Assembly(const Plan& plan, std::span<const double> q0, std::span<const double> v0) {
        strings_.emplace_back(plan, q0, v0);
    }
    // Strings on a bridge: one plan (and its string's properties) per string, at n = 0 from q0[s]
    // and v0[s]; the bridge's modes at rest.
    struct OnBridge {
        const Plan* plan;
        StringProperties string;
        std::span<const double> q0, v0;
    };
    Assembly(std::span<const OnBridge> strings, std::span<const BridgeModeSpec> bridge);

    std::size_t size() const { return strings_.size(); }
    VibratingString& string(std::size_t s) { return strings_[s]; }
    const VibratingString& string(std::size_t s) const { return strings_[s]; }

    // n -> n + 1 for every string: each string's phases in turn (with links between them, every
    // string's begin_step, then the joint solve of their contacts and links, then every end_step).
    void step() {
        if (bridge_) return step_on_bridge();
        for (VibratingString& s : strings_) s.step();
    }

    // Changes of string s's state between steps (a strike: VibratingString::perturb; a silence),
    // its end's projections of the state taken again, so that the bridge's next pull sees the
    // change and the balance stays exact from the next step on.
    void perturb(std::size_t s, std::span<const double> displacement, std::span<const double> velocity);
    void silence(std::size_t s);
    // String s's plan changed its damping (Plan::set_damping): the string restarted and its
    // end's loads, which hold the modes' decay, formed again. Allocates nothing.
    void damping_changed(std::size_t s);

    const Bridge* bridge() const { return bridge_ ? &*bridge_ : nullptr; }
    // Every string's and the bridge's modal coordinates that are subnormal (ModalState's).
    std::size_t subnormal_coordinates() const {
        std::size_t n = bridge_ ? bridge_->subnormal_coordinates() : 0;
        for (const VibratingString& s : strings_) n += s.subnormal_coordinates();
        return n;
    }
    // String s's energy H^{n-1/2} with its end's link energy (its contacts and played parts too).
    double string_energy(std::size_t s) const;
    // The whole assembly's balance terms: energy, what damping and contacts took, what gestures
    // and played parts gave (the bridge's loads on the strings are inside it, not counted).
    double energy() const;
    double dissipated() const;
    double work() const;

private:
    void step_on_bridge();

    std::vector<VibratingString> strings_;
    std::vector<BridgeEnd> ends_;
    std::optional<Bridge> bridge_;  // (an assembly copies whole, its bridge too)
    std::vector<double> pulls_, now_, before_;  // the pulls, w^n and w^{n-1} of the step
};

}  // namespace fretbuzz
