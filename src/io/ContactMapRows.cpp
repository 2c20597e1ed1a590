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

void ContactMapRows::emit_rows_before(long row) {
    for (; current_row_ < std::min(row, total_rows_); ++current_row_) {
        const long end_step = std::min((current_row_ + 1) * interval_, total_steps_);
        sink_(static_cast<double>(end_step) * dt_, row_);
        std::fill(row_.begin(), row_.end(), 0.0);
    }
}

void ContactMapRows::add(long step, std::span<const std::pair<std::size_t, double>> forces) {
    if (step < 1 || step > total_steps_) throw std::logic_error("ContactMapRows: step out of range");
    emit_rows_before((step - 1) / interval_);
    const double t = static_cast<double>(step) * dt_;
    for (const auto& [i, force] : forces) {
        row_.at(i) = std::max(row_[i], force);
        peak_[i] = std::max(peak_[i], force);
        if (steps_[i] == 0) first_[i] = t;
        last_[i] = t;
        ++steps_[i];
    }
}

void ContactMapRows::finish() { emit_rows_before(total_rows_); }

}  // namespace fretbuzz
