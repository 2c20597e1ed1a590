#include "fretbuzz/run/ResultRecorder.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fretbuzz {

void ResultRecorder::begin(const RunLayout& layout) {
    const Case& c = *layout.source;
    run_ = RecordedRun{};
    run_.observation_points_m = layout.observation_points_m;
    const auto rows = static_cast<std::size_t>(layout.steps / layout.output_stride) + 1;
    run_.time.reserve(rows);
    run_.observation.reserve(rows * run_.point_count());
    for (auto* v : {&run_.energy_time, &run_.energy, &run_.contact_energy, &run_.dissipated}) v->reserve(rows);
    run_.grid_x.resize(c.mode_count());
    for (std::size_t i = 0; i < c.mode_count(); ++i) run_.grid_x[i] = c.grid_point(i);
    run_.obstacle_height = c.obstacle_on_grid();
    const double never = std::numeric_limits<double>::quiet_NaN();
    run_.first_contact_s.assign(c.mode_count(), never);
    run_.last_contact_s.assign(c.mode_count(), never);
    run_.peak_contact_force.assign(c.mode_count(), 0.0);
}

void ResultRecorder::observation(double t, std::span<const double> u) {
    run_.time.push_back(t);
    run_.observation.insert(run_.observation.end(), u.begin(), u.end());
}

void ResultRecorder::energy(double t, double h, double contact, double dissipated) {
    run_.energy_time.push_back(t);
    run_.energy.push_back(h);
    run_.contact_energy.push_back(contact);
    run_.dissipated.push_back(dissipated);
}

void ResultRecorder::observation_y(double, std::span<const double> y) {
    run_.observation_y.insert(run_.observation_y.end(), y.begin(), y.end());
}

void ResultRecorder::polarisation_energy(double energy_y, double damping_y, double friction) {
    run_.energy_y.push_back(energy_y);
    run_.damping_y.push_back(damping_y);
    run_.friction.push_back(friction);
}

void ResultRecorder::contacts(double t, std::span<const std::pair<std::size_t, double>> forces) {
    for (const auto& [i, force] : forces) {
        if (std::isnan(run_.first_contact_s[i])) run_.first_contact_s[i] = t;
        run_.last_contact_s[i] = t;
        run_.peak_contact_force[i] = std::max(run_.peak_contact_force[i], force);
    }
}

void ResultRecorder::snapshot(double t, std::span<const double>, std::span<const double> u) {
    run_.snapshot_time.push_back(t);
    run_.snapshots.insert(run_.snapshots.end(), u.begin(), u.end());
}

}  // namespace fretbuzz
