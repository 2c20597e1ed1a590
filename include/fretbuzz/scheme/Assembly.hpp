#pragma once
// Strings stepped together, and what couples them. Each string (VibratingString) owns its plan's
// state, contacts and ledger; the assembly steps them in the same time step and sums their
// balances. Today it holds one string and nothing couples it (Stepper is its facade). A bridge
// with modes of its own, linked to each string's bridge end, would join here: its ModalState, a
// link per string as one more unknown of that string's joint contact solve (PointContact's pads
// are where such an unknown goes), the strings' solves taken together where a link couples them,
// and one balance: the strings' terms, the bridge's energy and damping, the links' energy.
#include <cstddef>
#include <span>
#include <vector>

#include "fretbuzz/scheme/VibratingString.hpp"

namespace fretbuzz {

class Assembly {
public:
    // One string on `plan`, at n = 0 from modal displacement q0 and velocity v0.
    Assembly(const Plan& plan, std::span<const double> q0, std::span<const double> v0) {
        strings_.emplace_back(plan, q0, v0);
    }

    std::size_t size() const { return strings_.size(); }
    VibratingString& string(std::size_t s) { return strings_[s]; }
    const VibratingString& string(std::size_t s) const { return strings_[s]; }

    // n -> n + 1 for every string: each string's phases in turn (with links between them, every
    // string's begin_step, then the joint solve of their contacts and links, then every end_step).
    void step() {
        for (VibratingString& s : strings_) s.step();
    }
private:
    std::vector<VibratingString> strings_;
};

}  // namespace fretbuzz
