#pragma once
// results.h5: everything a run produced, in one HDF5 file, streamed to disk as the run
// goes (chunked, extendible datasets; no signal is ever held whole in memory).
//
//   /                       attributes: format, format_version, case, fs_hz, dt_s, steps,
//                           output_rate_hz, output_stride, modes, length_m
//   /case/text              the case file text (UTF-8); attributes name, description
//   /time                   output times t_k (s), from 0
//   /observation/points_m   observation points x (m)
//   /observation/displacement   u(x_p, t_k), rows = /time, columns = points (m)
//   /observation/bridge_force   force of the string on the bridge end x = L at t_k (N, along +u)
//   /energy/{time,total,contact,dissipated}   H^{n-1/2}, its contact part and the
//                           cumulative dissipated energy (J), at t = (n - 1/2) dt
//   /energy/{finger,work,finger_loss}   with fingers or gestures: their part of total, the
//                           work of the external forces and motions, their part of
//                           dissipated (J), as energy.csv's finger_energy_J, work_J, finger_loss_J
//   /played/{kind,position_m,width_m}   with fingers or gestures: each one's kind ("finger",
//                           "force", "pluck", "pop"), pad centre and length (m)
//   /played/height          rows = /energy/time, columns = /played/kind: each finger's pad
//                           and each plucker's height (m), NaN where none
//   two polarisations: /observation/displacement_y (y, like displacement), /energy/{y,
//                           damping_y,friction} (J; total and dissipated include them),
//                           /modes_y/{frequency_hz,sigma_per_s}
//   /grid/x_m, /grid/obstacle_height_m        interior grid points and g(x_i) (-inf: none)
//   /contact/{row,point,max_force}   the contact map, sparse: one entry per interval
//                           (row r ends at step min((r+1) interval_steps, steps)) and grid
//                           point with a force, its largest force per unit length (N/m,
//                           float32); zero elsewhere. Attributes interval_steps, rows.
//   /contact/{first_s,last_s,steps,peak_force}   per grid point (NaN: never touched)
//   /snapshots/{time,displacement}   string shapes on the grid, if requested
//   /modes/{mode,frequency_hz,sigma_per_s,source}   the mode table the run used
//   /summary                the run summary as JSON text (same as summary.json)
//
// Every dataset has a `units` attribute ("1": a count or index; "text": a string). With
// provenance, the root also has fretbuzz_version, created_utc, command_line, platform and
// case_sha256 (of /case/text).
#include <filesystem>
#include <limits>
#include <memory>
#include <string>

#include "fretbuzz/output/SummaryWriter.hpp"
#include "fretbuzz/run/RunObserver.hpp"

namespace fretbuzz {

struct Hdf5WriterOptions {
    double snapshot_rate_hz = 0.0;  // 0: no snapshots
    double snapshot_until_s = std::numeric_limits<double>::infinity();  // stop storing shapes after this time
    // Contact-map rows follow the output rate, but never more often than this: at the
    // native output rate a dense map of every step would dwarf the rest of the file.
    double max_contact_map_rate_hz = 50000.0;
    // Also store the dense map (/contact/max_force_dense, rows x points): for checking readers.
    bool dense_contact_map = false;
    // Provenance and WAV gains for /summary and the root attributes.
    SummaryExtras extras{};
};

class Hdf5Writer : public RunObserver {
public:
    explicit Hdf5Writer(const std::filesystem::path& path, Hdf5WriterOptions options = {});
    ~Hdf5Writer() override;
    Hdf5Writer(const Hdf5Writer&) = delete;
    Hdf5Writer& operator=(const Hdf5Writer&) = delete;

    void begin(const RunLayout& layout) override;
    void observation(double t, std::span<const double> u) override;
    void observation_y(double t, std::span<const double> y) override;
    void polarisation_energy(double energy_y, double damping_y, double friction) override;
    void bridge_force(double t, double force) override;
    void energy(double t, double h, double contact, double dissipated) override;
    void finger_energy(double finger_energy, double work, double finger_loss) override;
    void played_heights(std::span<const double> heights) override;
    void contacts(double t, std::span<const std::pair<std::size_t, double>> forces) override;
    double snapshot_rate_hz() const override { return options_.snapshot_rate_hz; }
    double snapshot_until_s() const override { return options_.snapshot_until_s; }
    void snapshot(double t, std::span<const double> x, std::span<const double> u) override;
    void finish(const RunSummary& summary) override;

private:
    struct File;  // the open file and its datasets (keeps hdf5.h out of this header)
    void begin_played(const Case& c);
    std::filesystem::path path_;
    Hdf5WriterOptions options_;
    std::unique_ptr<File> file_;
};

}  // namespace fretbuzz

namespace fretbuzz {

// The case file text stored in a results.h5 (throws std::runtime_error if unreadable).
std::string read_case_text(const std::filesystem::path& results_h5);

}  // namespace fretbuzz
