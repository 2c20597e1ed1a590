#pragma once
// Keeps a whole run's outputs in memory, at the output rate, for scripting (the Python
// module hands them out as NumPy arrays). For long runs at high output rates prefer the
// streaming writers: this holds every output row.
#include <cstddef>
#include <utility>
#include <vector>

#include "fretbuzz/run/RunObserver.hpp"

namespace fretbuzz {

struct RecordedRun {
    std::vector<double> observation_points_m;
    std::vector<double> time;           // output times from t = 0 (s)
    std::vector<double> observation;    // u, row-major: time × points (m)
    std::vector<double> energy_time;    // (n - 1/2) dt (s)
    std::vector<double> energy;         // H^{n-1/2} (J)
    std::vector<double> contact_energy; // its contact part (J)
    std::vector<double> dissipated;     // cumulative dissipated energy (J)
    // Two polarisations: y like observation, and the y energy terms like energy (J).
    std::vector<double> observation_y, energy_y, damping_y, friction;
    std::vector<double> grid_x;         // interior grid points (m)
    std::vector<double> obstacle_height;
    // Per grid point: first and last contact times (NaN: never), peak force (N/m).
    std::vector<double> first_contact_s, last_contact_s, peak_contact_force;
    std::vector<double> snapshot_time;  // (s)
    std::vector<double> snapshots;      // u on the grid, row-major: snapshot × grid point (m)
    RunSummary summary;

    std::size_t point_count() const { return observation_points_m.size(); }
    std::size_t grid_size() const { return grid_x.size(); }
};

class ResultRecorder : public RunObserver {
public:
    explicit ResultRecorder(double snapshot_rate_hz = 0.0) : snapshot_rate_(snapshot_rate_hz) {}
    void begin(const RunLayout& layout) override;
    void observation(double t, std::span<const double> u) override;
    void energy(double t, double h, double contact, double dissipated) override;
    void observation_y(double t, std::span<const double> y) override;
    void polarisation_energy(double energy_y, double damping_y, double friction) override;
    void contacts(double t, std::span<const std::pair<std::size_t, double>> forces) override;
    double snapshot_rate_hz() const override { return snapshot_rate_; }
    void snapshot(double t, std::span<const double> x, std::span<const double> u) override;
    void finish(const RunSummary& summary) override { run_.summary = summary; }

    const RecordedRun& run() const { return run_; }
    RecordedRun take() { return std::move(run_); }

private:
    double snapshot_rate_;
    RecordedRun run_;
};

}  // namespace fretbuzz
