#pragma once
// The force gestures acting along a string's z polarisation (ForceProfile), as one part of its
// step: their loads of step n are known before the step, so they shift the free prediction the
// contacts are solved from (at grid points, exact points and pluckers' pads) and load the modes
// explicitly; their work is counted around the pass that moves the modes.
#include <cstddef>
#include <span>
#include <vector>

#include "fretbuzz/scheme/ForceProfile.hpp"
#include "fretbuzz/scheme/ModalState.hpp"
#include "fretbuzz/scheme/Plan.hpp"

namespace fretbuzz {

class ForceGestures {
public:
    // The plan's gestures, then one driven load (ForceProfile::drive) per shape of `driven`.
    explicit ForceGestures(const Plan& plan, std::span<const std::vector<double>> driven = {});

    bool empty() const { return gestures_.empty(); }
    std::size_t size() const { return gestures_.size(); }
    const std::vector<ForceProfile>& list() const { return gestures_; }
    // Whether any gesture's force may act at step n or later.
    bool act_from(long n) const;

    // The loads of step n; whether any is non-zero.
    bool load(long n);
    double load_of(std::size_t g) const { return load_[g]; }
    // Sets driven gesture g's load for the steps to come.
    void drive(std::size_t g, double load) { gestures_[g].drive(load); }
    // Driven gesture g's shape changed (same size), with its values at the exact points.
    void reshape_driven(std::size_t g, std::span<const double> shape);
    // The shift of the free prediction (m) the step's loads make at grid point i / exact point p.
    double at_grid(std::size_t i) const;
    double at_point(std::size_t p) const;
    // Their modal impulse k f_g s_g added to `impulse` (k = dt^2/mu).
    void add_impulse(double k, std::span<double> impulse) const;
    // The same impulse as rows for a pass: pass.push_rows and push_coefficients set to the loaded
    // gestures' shapes and k f_g.
    void push_rows(double k, kernels::StepPass& pass);
    // Around the pass that moves the modes with the loads: each loaded gesture's work (not a
    // driven load's: an assembly's balance counts the bridge's exchange as the link's energy).
    void begin_step(const ModalState& modes);
    void end_step(const ModalState& modes);
    // sum plus their work so far, added one by one (the ledger's order of sums).
    double add_work(double sum) const;

private:
    const Plan* plan_;
    std::vector<ForceProfile> gestures_;
    std::vector<double> load_;       // f^n of each gesture in the step being taken
    std::vector<double> at_points_;  // s_g . phi(x_p), gesture by gesture, point by point
    std::vector<const double*> rows_;  // the pass's push rows and coefficients (push_rows)
    std::vector<double> coefficients_;
    std::vector<double> row_;  // scratch: one row of S (reshape_driven)
};

}  // namespace fretbuzz
