#include "fretbuzz/io/CsvWriters.hpp"

#include <cerrno>
#include <charconv>
#include <cstring>
#include <stdexcept>

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

void ObservationCsvWriter::begin(const RunLayout& layout) {
    open_for_writing(out_, path_);
    line_ = "t_s";
    for (double x : layout.observation_points_m) {
        line_ += ',';  // the column is named by the point's x in metres
        append_number(line_, x);
    }
    if (layout.polarisations == 2)
        for (double x : layout.observation_points_m) {
            line_ += ",y_";  // y at that point
            append_number(line_, x);
        }
    y_.clear();
    line_ += '\n';
    out_ << line_;
}

void ObservationCsvWriter::observation_y(double, std::span<const double> y) { y_.assign(y.begin(), y.end()); }

void ObservationCsvWriter::observation(double t, std::span<const double> u) {
    line_.clear();
    append_number(line_, t);
    for (double v : u) {
        line_ += ',';
        append_number(line_, v);
    }
    for (double v : y_) {
        line_ += ',';
        append_number(line_, v);
    }
    line_ += '\n';
    out_ << line_;
}

void ObservationCsvWriter::finish(const RunSummary&) { close_checked(out_, path_); }

EnergyCsvWriter::EnergyCsvWriter(const std::filesystem::path& path) : path_(path) {}

void EnergyCsvWriter::begin(const RunLayout& layout) {
    open_for_writing(out_, path_);
    fingers_ = layout.fingers > 0;
    out_ << "t_s,energy_J,contact_energy_J,dissipated_J";
    // With fingers: energy_J includes finger_energy_J, dissipated_J includes finger_loss_J,
    // and energy_J - work_J + dissipated_J is constant.
    if (fingers_) out_ << ",finger_energy_J,work_J,finger_loss_J";
    // With two polarisations: energy_J = energy_z_J + energy_y_J + contact (+ fingers), and
    // dissipated_J includes damping_y_J and friction_J.
    two_polarisations_ = layout.polarisations == 2;
    if (two_polarisations_) out_ << ",energy_z_J,energy_y_J,damping_y_J,friction_J";
    out_ << '\n';
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
    line_.clear();
    for (double v : {t, h, contact, dissipated}) {
        if (!line_.empty()) line_ += ',';
        append_number(line_, v);
    }
    if (fingers_)
        for (double v : finger_terms_) {
            line_ += ',';
            append_number(line_, v);
        }
    if (two_polarisations_) {
        const double z = h - contact - y_terms_[0] - (fingers_ ? finger_terms_[0] : 0.0);
        for (double v : {z, y_terms_[0], y_terms_[1], y_terms_[2]}) {
            line_ += ',';
            append_number(line_, v);
        }
    }
    line_ += '\n';
    out_ << line_;
}

void EnergyCsvWriter::finish(const RunSummary&) { close_checked(out_, path_); }

BridgeForceCsvWriter::BridgeForceCsvWriter(const std::filesystem::path& path) : path_(path) {}

void BridgeForceCsvWriter::begin(const RunLayout&) {
    open_for_writing(out_, path_);
    out_ << "t_s,bridge_force_N\n";
}

void BridgeForceCsvWriter::bridge_force(double t, double force) {
    line_.clear();
    append_number(line_, t);
    line_ += ',';
    append_number(line_, force);
    line_ += '\n';
    out_ << line_;
}

void BridgeForceCsvWriter::finish(const RunSummary&) { close_checked(out_, path_); }

}  // namespace fretbuzz
