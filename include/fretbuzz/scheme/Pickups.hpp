#pragma once
// The rows of mode shapes read off a string's state: one observation row (a pickup, read after
// every step) and an output row's probes and bridge (read after free flights). The caller keeps
// the rows and may change their values, then says so again. Their products are formed by the
// pass that leaves the state (the observation) or by a flight's closing jump (every row), in
// that pass: one pass over the modes fewer per read.
#include <cstddef>
#include <span>
#include <vector>

#include "fretbuzz/scheme/ModalState.hpp"

namespace fretbuzz {

class Pickups {
public:
    // The observation row (its values may have changed: read again now).
    void observe(const double* row, const ModalState& modes);
    const double* row() const { return observed_row_; }
    // Its displacement in the current state, where a pass or a jump formed it.
    double* observed() { return &observed_; }
    double observed_value() const { return observed_; }
    void keep(const ModalState& modes);  // the observation from the state as it is
    // The observation now: as the pass formed it (fused), or from the state.
    double observation(bool fused, const ModalState& modes) const {
        if (observed_row_ == nullptr) no_row();
        return fused ? observed_ : modes.at(observed_row_);
    }

    // The rows read after flights (their values may have changed).
    void observe_rows(std::span<const double* const> rows);
    std::size_t row_count() const { return flight_rows_.size(); }
    // out[r] = rows[r] . q^n at step n: from the closing jump of a flight that ended there, else by products.
    void row_displacements(std::span<double> out, long n, const ModalState& modes) const;

    // What a flight's closing jump forms: the flight rows, then the observation row if any, into
    // landing_values(); landed(step) says it did at `step`.
    std::span<const double* const> landing_rows() const { return landing_rows_; }
    double* landing_values() { return landing_values_.data(); }
    void landed(long step);
    void forget() { flight_rows_step_ = -1; }  // the state changed from outside

private:
    void gather();
    [[noreturn]] static void no_row();

    const double* observed_row_ = nullptr;  // observe(): one row, or none
    double observed_ = 0.0;                 // its displacement in the current state (fused step)
    std::vector<const double*> flight_rows_;
    std::vector<const double*> landing_rows_;  // flight_rows_, then observed_row_ if any
    // Their products, formed by the closing jump of the flight that ended at step
    // flight_rows_step_. Kept because it pays: without it, every output row after a flight
    // takes a pass of its own (docs/performance.md, the outputs' rows).
    std::vector<double> landing_values_;
    long flight_rows_step_ = -1;
};

}  // namespace fretbuzz
