#pragma once
// Streaming CSV writers: observation.csv (t_s, one column per observation point) and
// energy.csv (t_s, energy_J, contact_energy_J, dissipated_J), bridge_force.csv. With two
// polarisations observation.csv adds y_<x> columns, energy.csv the energy_z_J, energy_y_J,
// damping_y_J and friction_J terms (energy_J and dissipated_J hold their sums). Numbers are
// written in shortest round-trip form, so nothing is lost; a thread of each file formats
// and writes the rows while the run goes on (see src/output/CsvFile.hpp).
#include <filesystem>
#include <fstream>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "fretbuzz/run/RunObserver.hpp"

namespace fretbuzz {

class CsvFile;

class ObservationCsvWriter : public RunObserver {
public:
    explicit ObservationCsvWriter(const std::filesystem::path& path);
    ~ObservationCsvWriter() override;
    void begin(const RunLayout& layout) override;
    void observation(double t, std::span<const double> u) override;
    void observation_y(double t, std::span<const double> y) override;
    void finish(const RunSummary&) override;

private:
    std::filesystem::path path_;
    std::unique_ptr<CsvFile> file_;
    std::vector<double> row_;
    std::size_t y_count_ = 0;  // y values (two polarisations), stored at the row's end before its u
};

class EnergyCsvWriter : public RunObserver {
public:
    explicit EnergyCsvWriter(const std::filesystem::path& path);
    ~EnergyCsvWriter() override;
    void begin(const RunLayout& layout) override;
    void energy(double t, double h, double contact, double dissipated) override;
    void finger_energy(double finger_energy, double work, double finger_loss) override;
    void polarisation_energy(double energy_y, double damping_y, double friction) override;
    void finish(const RunSummary&) override;

private:
    std::filesystem::path path_;
    std::unique_ptr<CsvFile> file_;
    std::vector<double> row_;
    bool fingers_ = false;
    bool two_polarisations_ = false;
    double finger_terms_[3] = {0.0, 0.0, 0.0};
    double y_terms_[3] = {0.0, 0.0, 0.0};
};

// bridge_force.csv (t_s, bridge_force_N): the force of the string on its bridge end.
class BridgeForceCsvWriter : public RunObserver {
public:
    explicit BridgeForceCsvWriter(const std::filesystem::path& path);
    ~BridgeForceCsvWriter() override;
    void begin(const RunLayout& layout) override;
    void bridge_force(double t, double force) override;
    void finish(const RunSummary&) override;

private:
    std::filesystem::path path_;
    std::unique_ptr<CsvFile> file_;
};

// Checked file writing: each throws runtime_error naming the file (and the system's
// reason, e.g. "No space left on device") when opening, writing, flushing or closing fails.
void open_for_writing(std::ofstream& out, const std::filesystem::path& path);
void close_checked(std::ofstream& out, const std::filesystem::path& path);
void write_text_file(const std::filesystem::path& path, std::string_view text);

// Appends the shortest decimal form of v that reads back to exactly v.
void append_number(std::string& line, double v);

}  // namespace fretbuzz
