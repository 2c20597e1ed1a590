#pragma once
// A string's end resting on a bridge (Bridge). The string keeps its modes of fixed ends; its
// motion is u = S q + w psi, psi(x) = x / L, w the bridge end's displacement, and the string's
// state is q' = q + g w with g = dx S^T psi, so that S q' is u itself on the grid (the contacts,
// fingers and pickups see the string where it is). In q' the bridge loads each mode with
//     q'^{n+1}_j - A_j q'^n_j + e_j q'^{n-1}_j = g_j ((2 - A_j) w^n - (1 - e_j) w^{n-1}) + (contacts),
// where w^{n+1} cancels: a load known before the step, which the string takes as driven force
// gestures (ForceGestures), its contacts solved with it exactly as with any gesture. The bridge
// sees the string's pull (Bridge), -mu (g . delta^2 q) / dt^2 less the mass term, in which every
// other force on the string (contacts, fingers, gestures, all acting on u = phi . q') cancels
// against its own push on the end (phi . g per unit of w): the pull needs only the string's free
// prediction, so the bridge steps first. The kinetic cross term of u = v + w psi, the end's
// share of the string's mass and its static stiffness k = T / L close the balance:
//     E_link = E_modal(q) - E_modal(q') + mu/dt^2 (g . d+q)(d+w) + mu G/(2 dt^2) (d+w)^2
//              + k/4 ((w^{n+1})^2 + (w^n)^2),    G = |g|^2, q = q' - g w,
// so that strings + bridge + links conserve the discrete energy exactly (lossless) or lose
// exactly their dampings.
#include <cstddef>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/scheme/ModalState.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/VibratingString.hpp"

namespace fretbuzz {

class BridgeEnd {
public:
    BridgeEnd(const Plan& plan, const StringProperties& string);

    // The driven loads' modal shapes, for the string's ForceGestures (after the plan's gestures).
    const std::vector<std::vector<double>>& load_shapes() const { return shapes_; }
    // Index of the first driven gesture in the string's ForceGestures.
    std::size_t first_gesture() const { return first_gesture_; }
    double stiffness() const { return stiffness_; }

    // The string's step n -> n + 1 with the loads of w^n and w^{n-1}; g . q'^{n+1} kept. A string
    // that nothing else acts on (a sympathetic string) takes it as one pass over its modes, which
    // forms the next pull's prediction too; any other steps its three phases.
    void step(VibratingString& string, double w_now, double w_before);
    // After the string's first step: g . q'^1 kept.
    void keep(const ModalState& modes);
    // After a change of the string's state between steps (a strike, a silence): g . q'^n and
    // g . q'^{n-1} (and the lossy part's) taken again from it.
    void retake(const ModalState& modes);
    // After the string's plan changed its damping (Plan::set_damping) and the string restarted:
    // the loads (they hold the modes' decay) formed again, in the string's gestures too, and
    // the projections taken anew. Allocates nothing.
    void reform(VibratingString& string);
    // Before the step n -> n + 1 (string at n, the end at w^n and w^{n-1}): the string's pull on
    // the bridge without its stiffness term, -mu/dt^2 g . (free q'^{n+1} + bridge load - 2 q'^n + q'^{n-1}).
    double pull(const VibratingString& string, double w_now, double w_before) const;
    // After the step, with w^{n+1} - w^{n-1}: the modes' damping acts on q = q' - g w, not on the
    // q' the string's ledger sees; the difference is added here (J).
    void correct_damping(double w_step2);
    double damping_correction() const { return damping_; }
    // E_link at n + 1/2 (after the step to n + 1; w^{n+1}, w^n the end's displacements).
    double energy(const ModalState& modes, double modal_energy, double w_next, double w_now) const;

private:
    // The loads of the step n -> n + 1 from w^n and w^{n-1}.
    template <class Gestures>
    void drive(Gestures& gestures, double w_now, double w_before) const {
        gestures.drive(first_gesture_, w_now);
        gestures.drive(first_gesture_ + 1, lossy_ ? -w_before : 0.0);
    }

    const Plan* plan_;
    std::vector<double> g_;
    std::vector<std::vector<double>> shapes_;  // the loads of w^n and w^{n-1} (the second 0 without losses)
    std::size_t first_gesture_;
    void form_loads();
    bool forecast_holds(const VibratingString& string) const {
        return forecast_.step == string.step_index() && forecast_.revision == string.revision();
    }

    std::vector<double> g_loss_;  // g_j (1 - e_j) (0 without losses)
    bool lossy_ = false;
    double mu_, dt_, stiffness_, g_norm2_;
    double load_now_ = 0.0, load_before_ = 0.0;  // g . (the bridge load's shape), per unit of w^n and w^{n-1}
    double loss_now_ = 0.0, loss_before_ = 0.0;  // the same with g_loss
    double loss_norm_ = 0.0;                     // sum_j (1 - e_j) g_j^2
    double x_[3] = {0.0, 0.0, 0.0};              // g . q' at n - 1, n, n + 1
    double y_[3] = {0.0, 0.0, 0.0};              // g_loss . q' at n - 1, n, n + 1
    double damping_ = 0.0;
    // g . and g_loss . (free q'^{n+1}) as the driven pass formed them, valid for the string at
    // step `step` and revision `revision` (a restart in between makes them stale).
    struct Forecast {
        double g = 0.0, loss = 0.0;
        long step = -1, revision = -1;
    };
    Forecast forecast_;
    mutable std::vector<double> q_, d_;
};

}  // namespace fretbuzz
