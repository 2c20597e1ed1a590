#pragma once
// Folds the contact forces of every time step into a map small enough to keep: for each
// interval of `interval_steps` steps, the largest force at each grid point that touched in
// it, and for each point its first and last contact times, its number of contact steps and
// its peak force. Only the non-zero entries of a row are handed out (most intervals of a
// run have no contact at all), as soon as their interval is over, so the map streams to
// disk in O(entries) rather than O(rows x points).
#include <cstddef>
#include <functional>
#include <span>
#include <utility>
#include <vector>

namespace fretbuzz {

class ContactMapRows {
public:
    // Row `row` (0-based; it ends at step min((row + 1) interval, total_steps)) and its
    // non-zero entries (grid index, largest force in N/m), in increasing grid index.
    using RowSink = std::function<void(long row, std::span<const std::pair<std::size_t, double>> entries)>;

    ContactMapRows(std::size_t points, long interval_steps, long total_steps, double dt, RowSink sink);
    // Forces (grid index, N/m) at time step `step` (1..total_steps), steps in increasing order.
    void add(long step, std::span<const std::pair<std::size_t, double>> forces);
    // Hands out the last row, if it has entries.
    void finish();

    long interval_steps() const { return interval_; }
    long total_rows() const { return total_rows_; }
    // Per grid point; NaN where the point never touched.
    const std::vector<double>& first_contact_s() const { return first_; }
    const std::vector<double>& last_contact_s() const { return last_; }
    const std::vector<long long>& contact_steps() const { return steps_; }
    const std::vector<double>& peak_force() const { return peak_; }

private:
    void emit_current_row();

    long interval_;
    long total_rows_;
    long total_steps_;
    double dt_;
    RowSink sink_;
    long current_row_ = -1;  // the row being filled (-1: none yet)
    std::vector<double> row_;                 // dense scratch, zero outside `touched_`
    std::vector<std::size_t> touched_;        // grid points with a force in the current row
    std::vector<std::pair<std::size_t, double>> entries_;
    std::vector<double> first_, last_, peak_;
    std::vector<long long> steps_;
};

}  // namespace fretbuzz
