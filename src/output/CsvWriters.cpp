#include "fretbuzz/output/CsvWriters.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <stdexcept>

#include "CsvFile.hpp"

namespace fretbuzz {

void append_number(std::string& line, double v) {
    char buffer[32];
    const auto result = std::to_chars(buffer, buffer + sizeof buffer, v);
    line.append(buffer, result.ptr);
}

namespace {
[[noreturn]] void write_failure(const std::filesystem::path& path) {
    const int error = errno;  // the failed write's, when the stream library left it
    throw std::runtime_error("cannot write " + path.string() + ": " +
                             (error != 0 ? std::strerror(error) : "the write failed (disk full?)"));
}
}  // namespace

void open_for_writing(std::ofstream& out, const std::filesystem::path& path) {
    errno = 0;
    out.open(path, std::ios::binary | std::ios::trunc);
    if (!out) write_failure(path);
}

void close_checked(std::ofstream& out, const std::filesystem::path& path) {
    errno = 0;
    out.flush();
    if (out) out.close();  // close() flushes the last buffer: it can fail too
    if (!out) write_failure(path);
}

void write_text_file(const std::filesystem::path& path, std::string_view text) {
    std::ofstream out;
    open_for_writing(out, path);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    close_checked(out, path);
}

ObservationCsvWriter::ObservationCsvWriter(const std::filesystem::path& path) : path_(path) {}

ObservationCsvWriter::~ObservationCsvWriter() = default;

void ObservationCsvWriter::begin(const RunLayout& layout) {
    std::string header = "t_s";
    for (double x : layout.observation_points_m) {
        header += ',';  // the column is named by the point's x in metres
        append_number(header, x);
    }
    y_count_ = layout.polarisations == 2 ? layout.observation_points_m.size() : 0;
    for (std::size_t p = 0; p < y_count_; ++p) {
        header += ",y_";  // y at that point
        append_number(header, layout.observation_points_m[p]);
    }
    header += '\n';
    row_.assign(1 + layout.observation_points_m.size() + y_count_, 0.0);
    file_ = std::make_unique<CsvFile>(path_, header, row_.size());
}

void ObservationCsvWriter::observation_y(double, std::span<const double> y) {
    std::copy(y.begin(), y.begin() + static_cast<std::ptrdiff_t>(std::min(y.size(), y_count_)), row_.end() - static_cast<std::ptrdiff_t>(y_count_));
}

void ObservationCsvWriter::observation(double t, std::span<const double> u) {
    if (u.size() + y_count_ + 1 != row_.size()) throw std::logic_error("ObservationCsvWriter: a row of the wrong width");
    row_[0] = t;
    std::copy(u.begin(), u.end(), row_.begin() + 1);
    file_->row(row_);
}

void ObservationCsvWriter::finish(const RunSummary&) { file_->close(); }

EnergyCsvWriter::EnergyCsvWriter(const std::filesystem::path& path) : path_(path) {}

EnergyCsvWriter::~EnergyCsvWriter() = default;

void EnergyCsvWriter::begin(const RunLayout& layout) {
    std::string header = "t_s,energy_J,contact_energy_J,dissipated_J";
    fingers_ = layout.fingers > 0;
    // With fingers: energy_J includes finger_energy_J, dissipated_J includes finger_loss_J,
    // and energy_J - work_J + dissipated_J is constant.
    if (fingers_) header += ",finger_energy_J,work_J,finger_loss_J";
    // With two polarisations: energy_J = energy_z_J + energy_y_J + contact (+ fingers), and
    // dissipated_J includes damping_y_J and friction_J.
    two_polarisations_ = layout.polarisations == 2;
    if (two_polarisations_) header += ",energy_z_J,energy_y_J,damping_y_J,friction_J";
    header += '\n';
    row_.assign(4 + (fingers_ ? 3 : 0) + (two_polarisations_ ? 4 : 0), 0.0);
    file_ = std::make_unique<CsvFile>(path_, header, row_.size());
}

void EnergyCsvWriter::polarisation_energy(double energy_y, double damping_y, double friction) {
    y_terms_[0] = energy_y;
    y_terms_[1] = damping_y;
    y_terms_[2] = friction;
}

void EnergyCsvWriter::finger_energy(double finger_energy, double work, double finger_loss) {
    finger_terms_[0] = finger_energy;
    finger_terms_[1] = work;
    finger_terms_[2] = finger_loss;
}

void EnergyCsvWriter::energy(double t, double h, double contact, double dissipated) {
    auto at = row_.begin();
    for (double v : {t, h, contact, dissipated}) *at++ = v;
    if (fingers_) at = std::copy(std::begin(finger_terms_), std::end(finger_terms_), at);
    if (two_polarisations_) {
        const double z = h - contact - y_terms_[0] - (fingers_ ? finger_terms_[0] : 0.0);
        for (double v : {z, y_terms_[0], y_terms_[1], y_terms_[2]}) *at++ = v;
    }
    file_->row(row_);
}

void EnergyCsvWriter::finish(const RunSummary&) { file_->close(); }

BridgeForceCsvWriter::BridgeForceCsvWriter(const std::filesystem::path& path) : path_(path) {}

BridgeForceCsvWriter::~BridgeForceCsvWriter() = default;

void BridgeForceCsvWriter::begin(const RunLayout&) { file_ = std::make_unique<CsvFile>(path_, "t_s,bridge_force_N\n", 2); }

void BridgeForceCsvWriter::bridge_force(double t, double force) {
    const double row[] = {t, force};
    file_->row(row);
}

void BridgeForceCsvWriter::finish(const RunSummary&) { file_->close(); }

}  // namespace fretbuzz
