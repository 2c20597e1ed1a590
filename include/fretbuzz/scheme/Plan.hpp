#pragma once
// Everything that stays fixed during a run, computed and checked once (the FFTW idea
// of planning before executing): the modal basis and its transform, the exact per-mode
// propagator, the obstacle on the grid, the contact law and the step size. The obstacle
// is held as the contact solve sees it: below the string (an obstacle above is mirrored).
// Planning refuses a sampling rate at which modes alias onto low frequencies under contact.
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/scheme/ModalBasis.hpp"
#include "fretbuzz/scheme/ModalPropagator.hpp"
#include "fretbuzz/scheme/PenaltyContact.hpp"

namespace fretbuzz {

struct PlanOptions {
    // Skip grid points that provably cannot touch the obstacle (see ContactScreen).
    // false gives the straightforward path: every point is solved at every step.
    bool screen_contacts = true;
    // Above this many points to evaluate, use the fast sine transform instead of rows of S.
    std::size_t transform_threshold = 0;  // 0: chosen from the grid size
    // Let FFTW time its candidate algorithms when planning (worth it for long runs).
    bool measure_transform = false;
};

class Plan {
public:
    Plan(const Case& c, double dt, PlanOptions options = {});

    std::size_t mode_count() const { return basis_.mode_count(); }
    double dt() const { return dt_; }
    double linear_density() const { return mu_; }
    const ModalBasis& basis() const { return basis_; }
    const ModalPropagator& propagator() const { return propagator_; }
    const PenaltyContact& contact() const { return contact_; }
    const std::vector<double>& obstacle() const { return obstacle_; }
    const PlanOptions& options() const { return options_; }
    std::size_t transform_threshold() const { return transform_threshold_; }
    // Points beyond which one sine transform is cheaper than rows of S, for N modes.
    static std::size_t default_transform_threshold(std::size_t modes);
    // dt^2 / mu: the factor from force per length to displacement in one step.
    double force_to_displacement() const { return dt_ * dt_ / mu_; }
    // What planning found doubtful but allowed (modes above fs/2, see SamplingCheck).
    const std::vector<std::string>& warnings() const { return warnings_; }
    // Grid points where an obstacle exists at all (g > -inf).
    const std::vector<std::size_t>& obstacle_points() const { return obstacle_points_; }
    // The fingers of the case (they press toward the obstacle side, see Finger).
    const std::vector<FingerSpec>& fingers() const { return fingers_; }
    // Prescribed forces on the string (force gestures).
    const std::vector<ForceSpec>& forces() const { return forces_; }

private:
    double dt_;
    double mu_;
    ModalBasis basis_;
    ModalPropagator propagator_;
    PenaltyContact contact_;
    std::vector<double> obstacle_;
    std::vector<std::size_t> obstacle_points_;
    std::vector<FingerSpec> fingers_;
    std::vector<ForceSpec> forces_;
    PlanOptions options_;
    std::size_t transform_threshold_;
    std::vector<std::string> warnings_;
};

}  // namespace fretbuzz
