#include "fretbuzz/output/Hdf5Writer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "ContactMapRows.hpp"
#include "Hdf5Objects.hpp"
#include "fretbuzz/output/SummaryWriter.hpp"

namespace fretbuzz {

namespace {
constexpr long long kFormatVersion = 2;  // 2: the contact map is stored sparsely
constexpr std::size_t kSignalChunkRows = 4096;
constexpr std::size_t kMapChunkRows = 64;
// Entries per chunk of the sparse map: zlib sets up (and clears) a few hundred KiB of state for
// every chunk it compresses, which at 4096 entries cost more than compressing them.
constexpr std::size_t kMapChunkEntries = 32768;
constexpr std::size_t kSnapshotChunkRows = 16;
constexpr std::size_t kWritebackRows = 16 * kSignalChunkRows;

// The unit of every dataset the writer makes.
constexpr std::pair<const char*, const char*> kUnits[] = {
    {"time", "s"},
    {"case/text", "text"},
    {"summary", "text"},
    {"observation/points_m", "m"},
    {"observation/displacement", "m"},
    {"observation/bridge_force", "N"},
    {"energy/time", "s"},
    {"energy/total", "J"},
    {"energy/contact", "J"},
    {"energy/dissipated", "J"},
    {"grid/x_m", "m"},
    {"grid/obstacle_height_m", "m"},
    {"contact/row", "1"},
    {"contact/point", "1"},
    {"contact/max_force", "N/m"},
    {"contact/max_force_dense", "N/m"},
    {"contact/first_s", "s"},
    {"contact/last_s", "s"},
    {"contact/steps", "1"},
    {"contact/peak_force", "N/m"},
    {"snapshots/time", "s"},
    {"snapshots/displacement", "m"},
    {"modes/mode", "1"},
    {"modes/frequency_hz", "Hz"},
    {"modes/sigma_per_s", "1/s"},
    {"modes/source", "text"},
};

constexpr std::pair<const char*, const char*> kPlayedUnits[] = {
    {"energy/finger", "J"},   {"energy/work", "J"},      {"played/kind", "text"},
    {"energy/finger_loss", "J"}, {"played/position_m", "m"}, {"played/width_m", "m"}, {"played/height", "m"},
};

// Pads a dense map with zero rows until it has `rows` rows.
void append_zero_rows(hdf5::GrowingDataset& dense, std::size_t rows) {
    if (dense.rows() >= rows) return;
    const std::vector<double> zero(dense.width(), 0.0);
    while (dense.rows() < rows) dense.append(zero);
}

// Chunks no longer than the run needs: HDF5 allocates, clears and writes a whole chunk
// even for the few rows of a short run (a 1 ms run's file was 300 KB of mostly padding).
std::size_t chunk_rows_for(std::size_t limit, long rows) {
    return std::clamp<std::size_t>(static_cast<std::size_t>(std::max(rows, 1L)), 1, limit);
}

long contact_interval_steps(const RunLayout& layout, double max_rate_hz) {
    const double fs = 1.0 / layout.dt;
    const auto fastest = static_cast<long>(std::ceil(fs / max_rate_hz - 1e-9));
    return std::max(layout.output_stride, std::max(1L, fastest));
}
}  // namespace

struct Hdf5Writer::File {
    hdf5::Handle file, case_group, observation, energy, grid, contact, snapshots, played;
    hdf5::GrowingDataset time, displacement;
    hdf5::GrowingDataset energy_time, energy_total, energy_contact, energy_dissipated;
    hdf5::GrowingDataset energy_finger, energy_work, energy_finger_loss, played_height;
    hdf5::GrowingDataset map_row, map_point, map_force, dense_map;
    hdf5::GrowingDataset snapshot_time, snapshot_shape;
    hdf5::GrowingDataset bridge_force;
    // Two polarisations: y at the observation points and the y energy terms.
    hdf5::GrowingDataset displacement_y, energy_y, damping_y, friction;
    std::optional<ContactMapRows> map;
    double dt = 0.0;
    std::size_t signal_chunk_rows = kSignalChunkRows;
    std::vector<double> observation_points;
    const Case* source = nullptr;
    // Last, so that it stops (and no chunk write is left running) before any dataset closes.
    WriteQueue queue;

    std::array<hdf5::GrowingDataset*, 21> datasets() {
        return {&time,          &displacement,  &energy_time,    &energy_total,       &energy_contact, &energy_dissipated,
                &map_row,       &map_point,     &map_force,      &dense_map,          &snapshot_time,  &snapshot_shape,
                &bridge_force,  &energy_finger, &energy_work,    &energy_finger_loss, &played_height,  &displacement_y,
                &energy_y,      &damping_y,     &friction};
    }
};

// The fingers' and gestures' own datasets (see the header), created only when the case has some.
void Hdf5Writer::begin_played(const Case& c) {
    using namespace hdf5;
    File& f = *file_;
    const std::size_t chunk = f.signal_chunk_rows;
    f.energy_finger = GrowingDataset(f.energy.get(), "finger", 0, chunk);
    f.energy_work = GrowingDataset(f.energy.get(), "work", 0, chunk);
    f.energy_finger_loss = GrowingDataset(f.energy.get(), "finger_loss", 0, chunk);
    f.played = create_group(f.file.get(), "played");
    std::vector<std::string> kind;
    std::vector<double> position, width;
    for (const FingerSpec& s : c.fingers) {
        kind.emplace_back("finger");
        position.push_back(s.position_m);
        width.push_back(s.width_m);
    }
    for (const ForceSpec& s : c.forces) {
        kind.emplace_back("force");
        position.push_back(s.position_m);
        width.push_back(s.width_m);
    }
    for (const PluckSpec& s : c.plucks) {
        kind.emplace_back(s.pop ? "pop" : "pluck");
        position.push_back(s.position_m);
        width.push_back(s.width_m);
    }
    write_strings(f.played.get(), "kind", kind);
    write_array(f.played.get(), "position_m", position);
    write_array(f.played.get(), "width_m", width);
    f.played_height = GrowingDataset(f.played.get(), "height", kind.size(), chunk);
}

Hdf5Writer::Hdf5Writer(const std::filesystem::path& path, Hdf5WriterOptions options) : path_(path), options_(options) {}

Hdf5Writer::~Hdf5Writer() = default;

void Hdf5Writer::begin(const RunLayout& layout) {
    using namespace hdf5;
    silence_error_printing();
    const Case& c = *layout.source;
    const std::size_t points = layout.observation_points_m.size();
    const std::size_t grid_size = c.mode_count();
    file_ = std::make_unique<File>();
    File& f = *file_;
    f.dt = layout.dt;
    f.signal_chunk_rows = chunk_rows_for(kSignalChunkRows, layout.steps / layout.output_stride + 1);
    const std::size_t chunk = f.signal_chunk_rows;
    f.source = layout.source;
    f.observation_points = layout.observation_points_m;
    f.file = create_file(path_.string());
    const hid_t root = f.file.get();
    write_attribute(root, "format", std::string("fretbuzz results"));
    write_attribute(root, "format_version", kFormatVersion);
    write_attribute(root, "case", c.name);
    write_attribute(root, "fs_hz", c.run.sample_rate_hz);
    write_attribute(root, "dt_s", layout.dt);
    write_attribute(root, "steps", static_cast<long long>(layout.steps));
    write_attribute(root, "output_rate_hz", layout.output_rate_hz);
    write_attribute(root, "output_stride", static_cast<long long>(layout.output_stride));
    write_attribute(root, "modes", static_cast<long long>(grid_size));
    write_attribute(root, "length_m", c.string.length_m);
    if (const auto& p = options_.extras.provenance) {
        write_attribute(root, "fretbuzz_version", p->version);
        write_attribute(root, "created_utc", p->created_utc);
        write_attribute(root, "command_line", p->command_line);
        write_attribute(root, "platform", p->platform);
        write_attribute(root, "case_sha256", sha256_hex(c.source_text));
    }
    {
        const Handle modes = create_group(root, "modes");
        std::vector<long long> mode(c.mode_count());
        for (std::size_t j = 0; j < mode.size(); ++j) mode[j] = static_cast<long long>(j + 1);
        std::vector<std::string> source;
        for (const ModeSource s : c.modes.source) source.push_back(to_string(s));
        write_array(modes.get(), "mode", mode);
        write_array(modes.get(), "frequency_hz", c.modes.frequency_hz);
        write_array(modes.get(), "sigma_per_s", c.modes.sigma_per_s);
        write_strings(modes.get(), "source", source);
    }

    f.case_group = create_group(root, "case");
    write_string(f.case_group.get(), "text", c.source_text);
    write_attribute(f.case_group.get(), "name", c.name);
    write_attribute(f.case_group.get(), "description", c.description);

    f.time = GrowingDataset(root, "time", 0, chunk);
    f.observation = create_group(root, "observation");
    write_array(f.observation.get(), "points_m", layout.observation_points_m);
    f.displacement = GrowingDataset(f.observation.get(), "displacement", points, chunk);
    f.bridge_force = GrowingDataset(f.observation.get(), "bridge_force", 0, chunk);

    f.energy = create_group(root, "energy");
    f.energy_time = GrowingDataset(f.energy.get(), "time", 0, chunk);
    f.energy_total = GrowingDataset(f.energy.get(), "total", 0, chunk);
    f.energy_contact = GrowingDataset(f.energy.get(), "contact", 0, chunk);
    f.energy_dissipated = GrowingDataset(f.energy.get(), "dissipated", 0, chunk);
    if (layout.polarisations == 2) {
        f.displacement_y = GrowingDataset(f.observation.get(), "displacement_y", points, chunk);
        f.energy_y = GrowingDataset(f.energy.get(), "y", 0, chunk);
        f.damping_y = GrowingDataset(f.energy.get(), "damping_y", 0, chunk);
        f.friction = GrowingDataset(f.energy.get(), "friction", 0, chunk);
        const Handle modes = create_group(root, "modes_y");
        const ModeTable y = c.y_modes();
        write_array(modes.get(), "frequency_hz", y.frequency_hz);
        write_array(modes.get(), "sigma_per_s", y.sigma_per_s);
    }

    if (layout.fingers > 0) begin_played(c);

    f.grid = create_group(root, "grid");
    std::vector<double> grid_x(grid_size);
    for (std::size_t i = 0; i < grid_size; ++i) grid_x[i] = c.grid_point(i);
    write_array(f.grid.get(), "x_m", grid_x);
    write_array(f.grid.get(), "obstacle_height_m", c.obstacle_on_grid());

    f.contact = create_group(root, "contact");
    const long interval = contact_interval_steps(layout, options_.max_contact_map_rate_hz);
    write_attribute(f.contact.get(), "interval_steps", static_cast<long long>(interval));
    // Sparse (coordinate list): one entry per interval and point with a force. The dense
    // map is zero almost everywhere; deflating its rows cost more than the simulation.
    f.map.emplace(grid_size, interval, layout.steps, layout.dt,
                  [&f](long row, std::span<const std::pair<std::size_t, double>> entries) {
                      for (const auto& [i, force] : entries) {
                          f.map_row.append(static_cast<double>(row));
                          f.map_point.append(static_cast<double>(i));
                          f.map_force.append(force);
                      }
                      if (f.dense_map.id() >= 0) {
                          append_zero_rows(f.dense_map, static_cast<std::size_t>(row));
                          std::vector<double> dense(f.dense_map.width(), 0.0);
                          for (const auto& [i, force] : entries) dense[i] = force;
                          f.dense_map.append(dense);
                      }
                  });
    // At most one entry per interval and point.
    const long map_rows = f.map->total_rows();
    const std::size_t entries = chunk_rows_for(kMapChunkEntries, map_rows * static_cast<long>(grid_size));
    f.map_row = GrowingDataset(f.contact.get(), "row", 0, entries, Storage::int64, true);
    f.map_point = GrowingDataset(f.contact.get(), "point", 0, entries, Storage::int64, true);
    f.map_force = GrowingDataset(f.contact.get(), "max_force", 0, entries, Storage::float32, true);
    if (options_.dense_contact_map)
        f.dense_map = GrowingDataset(f.contact.get(), "max_force_dense", grid_size, chunk_rows_for(kMapChunkRows, map_rows),
                                     Storage::float32, true);
    write_attribute(f.contact.get(), "rows", static_cast<long long>(map_rows));

    if (options_.snapshot_rate_hz > 0.0) {
        f.snapshots = create_group(root, "snapshots");
        write_attribute(f.snapshots.get(), "rate_hz", options_.snapshot_rate_hz);
        f.snapshot_time = GrowingDataset(f.snapshots.get(), "time", 0, kSnapshotChunkRows);
        f.snapshot_shape = GrowingDataset(f.snapshots.get(), "displacement", grid_size, kSnapshotChunkRows);
    }
    // From here to finish() every HDF5 call of this file is made by the queue's thread.
    for (GrowingDataset* d : f.datasets())
        if (d->id() >= 0) d->write_through(&f.queue);
}

void Hdf5Writer::observation(double t, std::span<const double> u) {
    file_->time.append(t);
    file_->displacement.append(u);
    // Every few chunks of rows (about 3 MB at audio rates), writeback of what HDF5 has
    // written so far, overlapping the run.
    if (file_->time.rows() % kWritebackRows == 0) file_->queue.post([file = file_->file.get()] { hdf5::start_writeback(file); });
}

void Hdf5Writer::observation_y(double, std::span<const double> y) { file_->displacement_y.append(y); }

void Hdf5Writer::polarisation_energy(double energy_y, double damping_y, double friction) {
    File& f = *file_;
    f.energy_y.append(energy_y);
    f.damping_y.append(damping_y);
    f.friction.append(friction);
}

void Hdf5Writer::bridge_force(double, double force) { file_->bridge_force.append(force); }

void Hdf5Writer::energy(double t, double h, double contact, double dissipated) {
    File& f = *file_;
    f.energy_time.append(t);
    f.energy_total.append(h);
    f.energy_contact.append(contact);
    f.energy_dissipated.append(dissipated);
}

void Hdf5Writer::finger_energy(double finger_energy, double work, double finger_loss) {
    File& f = *file_;
    f.energy_finger.append(finger_energy);
    f.energy_work.append(work);
    f.energy_finger_loss.append(finger_loss);
}

void Hdf5Writer::played_heights(std::span<const double> heights) { file_->played_height.append(heights); }

void Hdf5Writer::contacts(double t, std::span<const std::pair<std::size_t, double>> forces) {
    file_->map->add(std::lround(t / file_->dt), forces);
}

void Hdf5Writer::snapshot(double t, std::span<const double>, std::span<const double> u) {
    file_->snapshot_time.append(t);
    file_->snapshot_shape.append(u);
}

void Hdf5Writer::finish(const RunSummary& summary) {
    using namespace hdf5;
    File& f = *file_;
    f.map->finish();
    if (f.dense_map.id() >= 0) append_zero_rows(f.dense_map, static_cast<std::size_t>(f.map->total_rows()));
    for (GrowingDataset* d : f.datasets())
        if (d->id() >= 0) d->flush();
    f.queue.drain();  // HDF5 is this thread's again
    const hid_t contact = f.contact.get();
    write_array(contact, "first_s", f.map->first_contact_s());
    write_array(contact, "last_s", f.map->last_contact_s());
    write_array(contact, "steps", f.map->contact_steps());
    write_array(contact, "peak_force", f.map->peak_force());
    write_string(f.file.get(), "summary", summary_json(summary, f.observation_points, f.source, &options_.extras));
    for (const auto& [path, unit] : kUnits) write_attribute_at(f.file.get(), path, "units", unit);
    if (f.played.get() >= 0)
        for (const auto& [path, unit] : kPlayedUnits) write_attribute_at(f.file.get(), path, "units", unit);
    // Close the file now, every object before the file and every status checked: a full
    // disk shows here, and a file left half-open would make HDF5's own shutdown crash.
    const std::string name = path_.string();
    flush_file(f.file.get(), name);
    start_writeback(f.file.get());
    for (GrowingDataset* d : f.datasets()) d->close("write " + name);
    for (Handle* h : {&f.case_group, &f.observation, &f.energy, &f.grid, &f.contact, &f.snapshots, &f.played}) h->close("write " + name);
    f.file.close("write " + name);
    file_.reset();
}

}  // namespace fretbuzz

namespace fretbuzz {

std::string read_case_text(const std::filesystem::path& results_h5) {
    hdf5::silence_error_printing();
    const hdf5::Handle file = hdf5::open_file_for_reading(results_h5.string());
    return hdf5::read_string(file.get(), "case/text");
}

}  // namespace fretbuzz
