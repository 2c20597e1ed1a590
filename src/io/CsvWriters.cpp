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
    line_ += '\n';
    out_ << line_;
}

void ObservationCsvWriter::observation(double t, std::span<const double> u) {
    line_.clear();
    append_number(line_, t);
    for (double v : u) {
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
    out_ << '\n';
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
