#pragma once
// Folds the contact forces of every time step into a map small enough to keep: for each
// interval of `interval_steps` steps, the largest force at each grid point, and for each
// point its first and last contact times, its number of contact steps and its peak force.
// Rows are handed out as soon as their interval is over, so the map streams to disk.
#include <cstddef>
#include <functional>
#include <span>
#include <utility>
#include <vector>

namespace fretbuzz {

class ContactMapRows {
public:
    using RowSink = std::function<void(double interval_end_s, std::span<const double> max_force)>;

    ContactMapRows(std::size_t points, long interval_steps, long total_steps, double dt, RowSink sink);
    // Forces (grid index, N/m) at time step `step` (1..total_steps), steps in increasing order.
    void add(long step, std::span<const std::pair<std::size_t, double>> forces);
    // Hands out the remaining rows, up to the end of the run.
    void finish();

    long interval_steps() const { return interval_; }
    // Per grid point; NaN where the point never touched.
    const std::vector<double>& first_contact_s() const { return first_; }
    const std::vector<double>& last_contact_s() const { return last_; }
    const std::vector<long long>& contact_steps() const { return steps_; }
    const std::vector<double>& peak_force() const { return peak_; }

private:
    void emit_rows_before(long row);

    long interval_;
    long total_rows_;
    long total_steps_;
    double dt_;
    RowSink sink_;
    long current_row_ = 0;
    std::vector<double> row_;
    std::vector<double> first_, last_, peak_;
    std::vector<long long> steps_;
};

}  // namespace fretbuzz
