#pragma once
// Streaming CSV writers: observation.csv (t_s, one column per observation point) and
// energy.csv (t_s, energy_J, contact_energy_J, dissipated_J), bridge_force.csv. Rows go straight to disk;
// numbers are written in shortest round-trip form, so nothing is lost.
#include <filesystem>
#include <fstream>
#include <span>
#include <string>
#include <string_view>

#include "fretbuzz/run/RunObserver.hpp"

namespace fretbuzz {

class ObservationCsvWriter : public RunObserver {
public:
    explicit ObservationCsvWriter(const std::filesystem::path& path);
    void begin(const RunLayout& layout) override;
    void observation(double t, std::span<const double> u) override;
    void finish(const RunSummary&) override;

private:
    std::filesystem::path path_;
    std::ofstream out_;
    std::string line_;
};

class EnergyCsvWriter : public RunObserver {
public:
    explicit EnergyCsvWriter(const std::filesystem::path& path);
    void begin(const RunLayout& layout) override;
    void energy(double t, double h, double contact, double dissipated) override;
    void finger_energy(double finger_energy, double work, double finger_loss) override;
    void finish(const RunSummary&) override;

private:
    std::filesystem::path path_;
    std::ofstream out_;
    std::string line_;
    bool fingers_ = false;
    double finger_terms_[3] = {0.0, 0.0, 0.0};
};

// bridge_force.csv (t_s, bridge_force_N): the force of the string on its bridge end.
class BridgeForceCsvWriter : public RunObserver {
public:
    explicit BridgeForceCsvWriter(const std::filesystem::path& path);
    void begin(const RunLayout& layout) override;
    void bridge_force(double t, double force) override;
    void finish(const RunSummary&) override;

private:
    std::filesystem::path path_;
    std::ofstream out_;
    std::string line_;
};

// Checked file writing: each throws runtime_error naming the file (and the system's
// reason, e.g. "No space left on device") when opening, writing, flushing or closing fails.
void open_for_writing(std::ofstream& out, const std::filesystem::path& path);
void close_checked(std::ofstream& out, const std::filesystem::path& path);
void write_text_file(const std::filesystem::path& path, std::string_view text);

// Appends the shortest decimal form of v that reads back to exactly v.
void append_number(std::string& line, double v);

}  // namespace fretbuzz
