#include "ContactMapRows.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <utility>

namespace fretbuzz {

ContactMapRows::ContactMapRows(std::size_t points, long interval_steps, long total_steps, double dt, RowSink sink)
    : interval_(std::max(1L, interval_steps)),
      total_rows_((total_steps + interval_ - 1) / interval_),
      total_steps_(total_steps),
      dt_(dt),
      sink_(std::move(sink)),
      row_(points, 0.0),
      first_(points, std::numeric_limits<double>::quiet_NaN()),
      last_(points, std::numeric_limits<double>::quiet_NaN()),
      peak_(points, 0.0),
      steps_(points, 0) {}

void ContactMapRows::emit_current_row() {
    if (touched_.empty()) return;
    std::sort(touched_.begin(), touched_.end());
    entries_.clear();
    for (std::size_t i : touched_) {
        entries_.emplace_back(i, row_[i]);
        row_[i] = 0.0;
    }
    touched_.clear();
    sink_(current_row_, entries_);
}

void ContactMapRows::add(long step, std::span<const std::pair<std::size_t, double>> forces) {
    if (step < 1 || step > total_steps_) throw std::logic_error("ContactMapRows: step out of range");
    const long row = (step - 1) / interval_;
    if (row < current_row_) throw std::logic_error("ContactMapRows: steps out of order");
    if (row != current_row_) {
        emit_current_row();
        current_row_ = row;
    }
    const double t = static_cast<double>(step) * dt_;
    for (const auto& [i, force] : forces) {
        if (force <= 0.0) continue;  // only forces make entries (the law never gives f < 0)
        if (row_.at(i) == 0.0) touched_.push_back(i);
        row_[i] = std::max(row_[i], force);
        peak_[i] = std::max(peak_[i], force);
        if (steps_[i] == 0) first_[i] = t;
        last_[i] = t;
        ++steps_[i];
    }
}

void ContactMapRows::finish() { emit_current_row(); }

}  // namespace fretbuzz
