#include "fretbuzz/scheme/Pickups.hpp"

#include <algorithm>
#include <stdexcept>

namespace fretbuzz {

void Pickups::observe(const double* row, const ModalState& modes) {
    observed_row_ = row;
    keep(modes);  // (the row's values may have changed)
    gather();
}

void Pickups::keep(const ModalState& modes) {
    if (observed_row_ != nullptr) observed_ = modes.at(observed_row_);
}

void Pickups::no_row() { throw std::logic_error("Stepper::observation: no row to observe (call observe first)"); }

void Pickups::observe_rows(std::span<const double* const> rows) {
    flight_rows_.assign(rows.begin(), rows.end());
    flight_rows_step_ = -1;  // the rows' values may have changed
    gather();
}

void Pickups::gather() {
    landing_rows_ = flight_rows_;
    if (observed_row_ != nullptr) landing_rows_.push_back(observed_row_);
    landing_values_.resize(landing_rows_.size());
}

void Pickups::landed(long step) {
    flight_rows_step_ = step;
    if (observed_row_ != nullptr) observed_ = landing_values_.back();
}

void Pickups::row_displacements(std::span<double> out, long n, const ModalState& modes) const {
    if (out.size() != flight_rows_.size()) throw std::logic_error("Stepper::row_displacements: not the observed rows");
    if (flight_rows_step_ == n)
        std::copy(landing_values_.begin(), landing_values_.begin() + static_cast<long>(out.size()), out.begin());
    else
        kernels::dot_rows(flight_rows_.data(), flight_rows_.size(), modes.q().data(), modes.size(), out.data());
}

}  // namespace fretbuzz
