#pragma once
// The pluckers, each at its exact position (Pluck) pressing on its pad's
// mean displacement u_s = s . q. Alone on the string, a plucker's step is its own scalar solve;
// beside other pluckers, exact points, the grid's obstacle points or a finger, each is one more
// unknown of PointContact's solve (a PointContact::Pad), with its couplings s . phi(x_p),
// s . S_i and s_a . s_b formed once here. Their forces load the modes explicitly, as a gesture's.
// Plucker j is played part first() + j.
#include <algorithm>
#include <cstddef>
#include <span>
#include <vector>

#include "fretbuzz/scheme/ForceGestures.hpp"
#include "fretbuzz/scheme/ModalState.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/PlayedParts.hpp"
#include "fretbuzz/scheme/StepRecord.hpp"

namespace fretbuzz {

class ExactPluckers {
public:
    ExactPluckers(const Plan& plan, const PlayedParts& parts, const ForceGestures& gestures);

    std::size_t size() const { return count_; }
    std::size_t first() const { return first_; }
    bool is(std::size_t part) const { return part >= first_ && part < first_ + count_; }
    bool on(const PlayedParts& parts, std::size_t j) const { return j < count_ && parts.on(first_ + j); }
    bool any_on(const PlayedParts& parts) const;
    Pluck& pluck(PlayedParts& parts, std::size_t j) const { return static_cast<Pluck&>(parts[first_ + j]); }
    // Plucker j starts from u_s at levels n - 1 and n.
    void start(PlayedParts& parts, std::size_t j, double u_before, double u_now) const;
    // Every one on the string starts from the state as it is (a restart).
    void restart(PlayedParts& parts, const ModalState& modes) const;

    // The step's acting pluckers (those gone are off for good); whether there are any.
    bool act(PlayedParts& parts) { return count_ != 0 && gather(parts); }
    std::size_t acting() const { return acting_.size(); }
    void clear_loads() {
        if (count_ != 0) std::fill(load_.begin(), load_.end(), 0.0);
    }
    // The one acting plucker with nothing beside it: its own solve; returns the Psi it adds.
    double solve_alone(PlayedParts& parts, const ModalState& modes, const ForceGestures& gestures, long n,
                       StepRecord& record);
    // The acting pluckers as PointContact's pads, each prepared for step n (with_grid: their
    // couplings to the grid points too); conclude() takes each one's solution.
    std::span<PointContact::Pad> pads(PlayedParts& parts, const ModalState& modes, const ForceGestures& gestures, long n,
                                      bool loaded, bool with_grid);
    void conclude(PlayedParts& parts, long n, StepRecord& record);

    // Their loads of the step: into the modal impulse (k = dt^2/mu), and report(x, force) for each
    // that pushed (N at its position).
    void add_impulse(PlayedParts& parts, double k, std::span<double> impulse) const;
    template <class Report>
    void each_force(const Plan& plan, Report&& report) const {
        for (std::size_t j = 0; j < count_; ++j)
            if (load_[j] != 0.0) report(plan.plucks()[j].position_m, load_[j]);
    }

private:
    // w_s = s . (free q^{n+1}), shifted by the gestures' loads of the step (before the pluckers' own).
    double prediction(const PlayedParts& parts, std::size_t j, const ModalState& modes, const ForceGestures& gestures,
                      bool loaded) const;
    void take_force(PlayedParts& parts, std::size_t j, double force, StepRecord& record);
    bool gather(PlayedParts& parts);

    const Plan* plan_;
    std::size_t first_ = 0, count_ = 0;
    std::vector<double> load_;              // each one's force on the string in this step (N)
    std::vector<double> gesture_at_pluck_;  // s_g . s_j, gesture by gesture, plucker by plucker
    std::vector<double> at_points_;         // s_j . phi(x_p), plucker by plucker, point by point
    std::vector<double> at_grid_;           // s_j . S_i, plucker by plucker (beside an obstacle or a finger on the grid)
    std::vector<double> cross_;             // s_j . s_b, plucker by plucker
    std::vector<std::size_t> acting_;       // scratch: those on the string in this step
    std::vector<PointContact::Pad> pads_;   // scratch: them as PointContact's pads
    std::vector<double> pad_cross_;         // scratch: their s_a . s_b, pad by pad
};

}  // namespace fretbuzz
