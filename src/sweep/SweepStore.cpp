#include "fretbuzz/sweep/SweepStore.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>

#include "../FileDescriptor.hpp"
#include "../output/Hdf5Objects.hpp"
#include "fretbuzz/Error.hpp"

namespace fretbuzz {

namespace fs = std::filesystem;

namespace {

std::string read_file(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

// What a temporary file of this store is called: NAME.tmp-PID-THREAD beside NAME.
constexpr std::string_view kTemporaryMark = ".tmp-";

std::string system_error_text(const std::string& what, const fs::path& path, int error) {
    return what + " " + path.string() + ": " + std::strerror(error);
}

// Writes text to a temporary file beside path, flushes it to disk and renames it into
// place: readers (and a resumed sweep) see the whole file or none. On failure (a full
// disk) the temporary file is removed and the error says why.
void write_atomically(const fs::path& path, const std::string& text) {
    std::ostringstream tmp_name;
    tmp_name << path.filename().string() << kTemporaryMark << ::getpid() << "-" << std::this_thread::get_id();
    const fs::path tmp = path.parent_path() / tmp_name.str();
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) throw std::runtime_error(system_error_text("cannot write", tmp, errno));
    const auto fail = [&](const char* what) {
        const int error = errno;
        ::close(fd);
        ::unlink(tmp.c_str());
        throw std::runtime_error(system_error_text(what, path, error));
    };
    if (const int error = write_fully(fd, text.data(), text.size()); error != 0) {
        errno = error;
        fail("cannot write");
    }
    if (::fsync(fd) != 0) fail("cannot flush");
    if (::close(fd) != 0) {
        const int error = errno;
        ::unlink(tmp.c_str());
        throw std::runtime_error(system_error_text("cannot flush", path, error));
    }
    if (::rename(tmp.c_str(), path.c_str()) != 0) {
        const int error = errno;
        ::unlink(tmp.c_str());
        throw std::runtime_error(system_error_text("cannot rename a finished file to", path, error));
    }
}

// The temporary files a sweep stopped mid-write (a full disk, a kill) left in dir.
std::size_t remove_temporaries_in(const fs::path& dir) {
    std::size_t removed = 0;
    std::error_code ec;
    for (const fs::directory_entry& entry : fs::directory_iterator(dir, ec)) {
        if (fs::is_regular_file(entry.symlink_status(ec)) &&
            entry.path().filename().string().find(kTemporaryMark) != std::string::npos && fs::remove(entry.path(), ec))
            ++removed;
    }
    return removed;
}

// The sweep's runs/ folder is its own: a symbolic link there is refused, never written
// through nor cleaned.
void refuse_linked_runs(const fs::path& dir) {
    std::error_code ec;
    const fs::file_status runs = fs::symlink_status(dir / "runs", ec);
    if (fs::is_symlink(runs) || (fs::exists(runs) && !fs::is_directory(runs)))
        throw InputError("--out " + dir.string() + ": " + (dir / "runs").string() + " is " +
                         (fs::is_symlink(runs) ? "a symbolic link" : "not a folder") +
                         "; a sweep keeps its runs in a folder of its own and neither follows nor deletes a link there: "
                         "move it away, or give another folder");
}

std::string shortest(double v) { return std::isfinite(v) ? sweep_number_text(v) : std::string(); }

std::string csv_field(const std::string& text) {
    if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
    std::string quoted = "\"";
    for (char ch : text) quoted += ch == '"' ? std::string("\"\"") : std::string(1, ch);
    return quoted + "\"";
}

bool parse_number(const std::string& text, double& value) {
    if (text.empty()) return false;
    const auto r = std::from_chars(text.data(), text.data() + text.size(), value);
    return r.ec == std::errc() && r.ptr == text.data() + text.size();
}

}  // namespace

// An exclusive flock(2) on DIR/sweep.lock, held while the store lives: one process at a
// time writes a sweep's folder. The kernel drops it when the process ends, however it ends.
struct SweepStore::Lock {
    int fd = -1;
    ~Lock() {
        if (fd >= 0) ::close(fd);
    }
};

std::shared_ptr<SweepStore::Lock> SweepStore::lock(const fs::path& dir) {
    const fs::path path = dir / "sweep.lock";
    auto held = std::make_shared<Lock>();
    held->fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (held->fd < 0)
        throw InputError("--out " + dir.string() + ": the output directory is not writable (" +
                         system_error_text("cannot create", path, errno) + ")");
    if (::flock(held->fd, LOCK_EX | LOCK_NB) != 0) {
        if (errno == EWOULDBLOCK)
            throw InputError("--out " + dir.string() +
                             ": another fretbuzz sweep is writing this directory (it holds " + path.string() +
                             "); wait for it to finish, or stop it and finish the sweep with --resume");
        throw std::runtime_error(system_error_text("cannot lock", path, errno));
    }
    return held;
}

std::size_t SweepStore::remove_stale_files(const fs::path& dir) {
    const std::shared_ptr<Lock> held = lock(dir);
    refuse_linked_runs(dir);
    return remove_temporaries_in(dir) + remove_temporaries_in(dir / "runs");
}

SweepStore::SweepStore(const SweepSpec& spec, fs::path dir, bool resume) : spec_(spec), dir_(std::move(dir)) {
    const fs::path spec_copy = dir_ / "sweep.toml";
    std::error_code ec;
    if (fs::exists(dir_, ec) && !fs::is_directory(dir_, ec))
        throw InputError("--out " + dir_.string() + ": exists and is not a directory");
    refuse_linked_runs(dir_);
    fs::create_directories(dir_ / "runs", ec);
    if (ec) throw InputError("--out " + dir_.string() + ": cannot create the output directory (" + ec.message() + ")");
    lock_ = lock(dir_);  // before anything in it is read or written
    if (fs::exists(spec_copy, ec)) {
        if (!resume)
            throw InputError("--out " + dir_.string() +
                             " already holds a sweep; add --resume to finish it, or choose another directory");
        if (read_file(spec_copy) != spec.text)
            throw InputError("--resume: " + dir_.string() + " holds a different sweep (its sweep.toml is not " +
                             spec.source_name + ")");
        // What an earlier attempt left half-written (stopped by a full disk or a kill): this
        // process holds the lock, so no other is writing them.
        remove_temporaries_in(dir_);
        remove_temporaries_in(dir_ / "runs");
        return;
    }
    try {
        write_atomically(spec_copy, spec.text);
    } catch (const std::exception& e) {
        throw InputError("--out " + dir_.string() + ": the output directory is not writable (" + e.what() + ")");
    }
}

fs::path SweepStore::row_path(std::size_t index) const {
    char name[32];
    std::snprintf(name, sizeof name, "%06zu.json", index);
    return dir_ / "runs" / name;
}

fs::path SweepStore::audio_dir(std::size_t index) const {
    return row_path(index).replace_extension();
}

std::vector<std::size_t> SweepStore::missing() const {
    std::vector<std::size_t> indices;
    for (std::size_t k = 0; k < spec_.runs.size(); ++k)
        if (!fs::exists(row_path(k))) indices.push_back(k);
    return indices;
}

std::size_t SweepStore::present() const { return spec_.runs.size() - missing().size(); }

void SweepStore::record(const SweepRow& row) const { write_atomically(row_path(row.index), row_to_json(row) + "\n"); }

std::vector<SweepRow> SweepStore::rows_present() const {
    std::vector<SweepRow> rows;
    for (std::size_t k = 0; k < spec_.runs.size(); ++k) {
        const fs::path path = row_path(k);
        if (!fs::exists(path)) continue;
        SweepRow row = row_from_json(read_file(path));
        if (row.index != k) throw InputError(path.string() + ": holds run " + std::to_string(row.index));
        rows.push_back(std::move(row));
    }
    return rows;
}

std::vector<SweepRow> SweepStore::rows() const {
    std::vector<SweepRow> rows = rows_present();
    if (rows.size() != spec_.runs.size())
        throw InputError(dir_.string() + ": " + std::to_string(spec_.runs.size() - rows.size()) +
                         " runs have no results yet; finish the sweep with --resume");
    return rows;
}

std::string sweep_table_csv(const SweepSpec& spec, const std::vector<SweepRow>& rows) {
    std::ostringstream csv;
    csv << "run";
    for (const std::string& key : spec.parameter_keys) csv << ',' << csv_field(key);
    csv << ",status,error,features";
    for (const std::string& name : sweep_metric_names()) csv << ',' << name;
    csv << '\n';
    for (const SweepRow& row : rows) {
        csv << row.index;
        for (const std::string& v : row.values) csv << ',' << csv_field(v);
        csv << ',' << (row.ok ? "ok" : "failed") << ',' << csv_field(row.error) << ',' << row.features;
        for (double m : row.metrics) csv << ',' << shortest(m);
        csv << '\n';
    }
    return csv.str();
}

void SweepStore::write_table() const {
    const std::vector<SweepRow> all = rows();
    write_atomically(dir_ / "results.csv", sweep_table_csv(spec_, all));

    // results.h5: group "table", one dataset per column (numbers as float64, text as
    // UTF-8 strings), and the column order in its "columns" attribute.
    const fs::path h5 = dir_ / "results.h5";
    const fs::path tmp = dir_ / ("results.h5" + std::string(kTemporaryMark) + std::to_string(::getpid()));
    try {
        hdf5::silence_error_printing();
        const hdf5::Handle file = hdf5::create_file(tmp.string());
        const hdf5::Handle table = hdf5::create_group(file.get(), "table");
        std::string columns = "run";
        std::vector<long long> index;
        for (const SweepRow& row : all) index.push_back(static_cast<long long>(row.index));
        hdf5::write_array(table.get(), "run", index);
        for (std::size_t p = 0; p < spec_.parameter_keys.size(); ++p) {
            std::vector<std::string> texts;
            std::vector<double> numbers;
            bool numeric = true;
            for (const SweepRow& row : all) {
                double v = 0.0;
                numeric = numeric && parse_number(row.values[p], v);
                numbers.push_back(v);
                texts.push_back(row.values[p]);
            }
            if (numeric)
                hdf5::write_array(table.get(), spec_.parameter_keys[p], numbers);
            else
                hdf5::write_strings(table.get(), spec_.parameter_keys[p], texts);
            columns += "," + spec_.parameter_keys[p];
        }
        std::vector<std::string> status, error, features;
        for (const SweepRow& row : all) {
            status.push_back(row.ok ? "ok" : "failed");
            error.push_back(row.error);
            features.push_back(row.features);
        }
        hdf5::write_strings(table.get(), "status", status);
        hdf5::write_strings(table.get(), "error", error);
        hdf5::write_strings(table.get(), "features", features);
        columns += ",status,error,features";
        for (std::size_t m = 0; m < sweep_metric_names().size(); ++m) {
            std::vector<double> values;
            for (const SweepRow& row : all) values.push_back(row.metrics[m]);
            hdf5::write_array(table.get(), sweep_metric_names()[m], values);
            columns += "," + sweep_metric_names()[m];
        }
        hdf5::write_attribute(table.get(), "columns", columns);
        hdf5::write_string(file.get(), "sweep.toml", spec_.text);
    } catch (...) {
        std::error_code ec;
        fs::remove(tmp, ec);
        throw;
    }
    if (::rename(tmp.c_str(), h5.c_str()) != 0) {
        const int error = errno;
        ::unlink(tmp.c_str());
        throw std::runtime_error(system_error_text("cannot rename a finished file to", h5, error));
    }
}

}  // namespace fretbuzz
