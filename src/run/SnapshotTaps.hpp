#pragma once
// The string's shape on the grid for the observers that ask for it (RunObserver's
// snapshot_rate_hz, up to snapshot_until_s), at the steps their rates fall on. Both laws' runs
// take them the same way; a free flight must not jump over a step one is due at.
#include <span>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/run/RunObserver.hpp"
#include "fretbuzz/scheme/Plan.hpp"

namespace fretbuzz {

class SnapshotTaps {
public:
    SnapshotTaps(const Case& c, const Plan& plan, std::span<RunObserver* const> observers);
    bool empty() const { return taps_.empty(); }
    // Whether a snapshot falls on a step after step n and before step n + steps.
    bool due_within(long n, long steps) const;
    // At step n (time t), the modal displacement q's shape to each observer due then.
    void report(long n, double t, std::span<const double> q);

private:
    struct Tap {
        RunObserver* observer;
        long stride;
        long last_step;  // no snapshots after this step
    };
    const Plan& plan_;
    std::vector<Tap> taps_;
    std::vector<double> x_, u_;
};

}  // namespace fretbuzz
