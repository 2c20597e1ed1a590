#include "fretbuzz/output/OutputDirectory.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <climits>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <random>
#include <set>
#include <stdexcept>

#include "fretbuzz/Error.hpp"

namespace fretbuzz {

namespace fs = std::filesystem;

namespace {

constexpr std::string_view kStagingPrefix = ".fretbuzz-staging-";
constexpr std::string_view kLockPrefix = ".fretbuzz-lock-";
constexpr std::string_view kOldStagingPrefix = ".fretbuzz-partial-";  // inside --out, before staging moved beside it
constexpr std::size_t kLeafInName = 100;  // keeps the staging name under NAME_MAX

std::string system_message(int error) { return std::strerror(error); }

[[noreturn]] void io_failure(const std::string& what, const fs::path& path, int error) {
    throw std::runtime_error("cannot " + what + " " + path.string() + ": " + system_message(error));
}

// Names are limited by the file system; a clear message beats ENAMETOOLONG from deep inside.
void check_name_lengths(const fs::path& dir) {
    if (dir.string().size() >= PATH_MAX)
        throw InputError("--out " + dir.string().substr(0, 64) + "...: the path is longer than " +
                         std::to_string(PATH_MAX - 1) + " bytes");
    for (const fs::path& part : dir)
        if (part.string().size() > NAME_MAX)
            throw InputError("--out: the name '" + part.string().substr(0, 32) + "...' is " +
                             std::to_string(part.string().size()) + " bytes long; names may have at most " +
                             std::to_string(NAME_MAX) + " bytes");
}

void fsync_path(const fs::path& path, bool directory) {
    const int fd = ::open(path.c_str(), (directory ? O_RDONLY | O_DIRECTORY : O_RDONLY) | O_CLOEXEC);
    if (fd < 0) io_failure("open", path, errno);
    const int status = ::fsync(fd);
    const int error = errno;
    ::close(fd);
    if (status != 0) io_failure("write", path, error);
}

bool lock_is_free(const fs::path& lock) {
    const int fd = ::open(lock.c_str(), O_RDWR | O_CLOEXEC | O_NOFOLLOW);
    if (fd < 0) return errno == ENOENT;
    const bool free = ::flock(fd, LOCK_EX | LOCK_NB) == 0;
    ::close(fd);
    return free;
}

bool process_is_gone(const std::string& pid_text) {
    try {
        const int pid = std::stoi(pid_text);
        return pid > 0 && ::kill(pid, 0) != 0 && errno == ESRCH;
    } catch (const std::exception&) {
        return false;
    }
}

std::string random_tag() {
    std::random_device device;
    return std::to_string(::getpid()) + "-" + std::to_string(device() % 1000000);
}

// Removes stale staging folders in `parent` (any directory's); counts them.
std::size_t remove_stale_in(const fs::path& parent) {
    std::size_t removed = 0;
    std::error_code ec;
    std::vector<fs::path> entries;
    for (const fs::directory_entry& e : fs::directory_iterator(parent, ec)) entries.push_back(e.path());
    for (const fs::path& p : entries) {
        const std::string name = p.filename().string();
        if (name.starts_with(kStagingPrefix)) {
            const fs::path lock = parent / (std::string(kLockPrefix) + name.substr(kStagingPrefix.size()));
            if (!lock_is_free(lock)) continue;
            fs::remove_all(p, ec);
            fs::remove(lock, ec);
            ++removed;
        } else if (name.starts_with(kLockPrefix)) {
            // A lock alone is either left over or a run's that has not locked it yet (the
            // lock comes first): only old ones go.
            const fs::path staging = parent / (std::string(kStagingPrefix) + name.substr(kLockPrefix.size()));
            const auto age = fs::file_time_type::clock::now() - fs::last_write_time(p, ec);
            if (!ec && age > std::chrono::minutes(1) && !fs::exists(staging, ec) && lock_is_free(p)) fs::remove(p, ec);
        }
    }
    return removed;
}

// Staging folders an older fretbuzz left inside the output directory itself.
std::size_t remove_old_style_in(const fs::path& dir) {
    std::size_t removed = 0;
    std::error_code ec;
    std::vector<fs::path> stale;
    for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
        const std::string name = e.path().filename().string();
        if (name.starts_with(kOldStagingPrefix) && process_is_gone(name.substr(kOldStagingPrefix.size())))
            stale.push_back(e.path());
    }
    for (const fs::path& p : stale) removed += fs::remove_all(p, ec) > 0 ? 1 : 0;
    return removed;
}

bool is_fretbuzz_folder(const std::string& name) {
    return name.starts_with(kOldStagingPrefix) || name.starts_with(kStagingPrefix);
}

}  // namespace

bool is_run_output_name(const std::string& name) {
    static const std::set<std::string> fixed = {
        "observation.csv", "energy.csv",  "bridge_force.csv",      "results.h5",      "summary.json",
        "report.html",     "signal.png",  "signal_all_points.png", "spectrogram.png", "energy.png",
        "contactogram.png", "snapshots.png", "animation.gif",       "animation.mp4"};
    if (fixed.contains(name)) return true;
    return name.ends_with(".wav") && (name.starts_with("audio") || name.starts_with("velocity"));
}

std::size_t remove_stale_staging(const fs::path& dir) {
    std::error_code ec;
    const fs::path absolute = fs::absolute(dir, ec).lexically_normal();
    const fs::path target = absolute.has_filename() ? absolute : absolute.parent_path();
    std::size_t removed = remove_stale_in(target.parent_path());
    if (fs::is_directory(target, ec)) removed += remove_stale_in(target) + remove_old_style_in(target);
    return removed;
}

OutputDirectory::OutputDirectory(const fs::path& dir) : dir_(dir) {
    if (dir.empty()) throw InputError("--out: the output directory name is empty");
    check_name_lengths(dir);
    std::error_code ec;
    const fs::file_status status = fs::status(dir_, ec);
    if (fs::exists(status) && !fs::is_directory(status))
        throw InputError("--out " + dir_.string() + ": exists and is not a directory");
    const bool exists = fs::exists(status);
    target_ = exists ? fs::canonical(dir_, ec) : fs::absolute(dir_, ec).lexically_normal();
    if (!target_.has_filename()) target_ = target_.parent_path();
    if (ec || target_ == target_.root_path())
        throw InputError("--out " + dir_.string() + ": cannot be used as an output directory");
    const fs::path cwd = fs::current_path(ec);
    if (exists && !ec && (cwd == target_ || cwd.string().starts_with(target_.string() + "/")))
        throw InputError("--out " + dir_.string() +
                         ": is the current directory or one of its parents; the output directory is replaced as a "
                         "whole, give a folder of its own");
    if (exists) {
        for (const fs::directory_entry& e : fs::directory_iterator(target_, ec)) {
            const std::string name = e.path().filename().string();
            if (e.is_directory(ec) && !e.is_symlink(ec) && !is_fretbuzz_folder(name))
                throw InputError("--out " + dir_.string() + ": holds a folder '" + name +
                                 "' that fretbuzz did not write; the output directory is replaced as a whole, give "
                                 "a new folder, an empty one or an earlier output directory");
        }
    }

    // Missing parents (a/b for --out a/b/c), outermost first, to remove if the run fails.
    const fs::path parent = target_.parent_path();
    std::vector<fs::path> missing;
    for (fs::path p = parent; !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
        missing.insert(missing.begin(), p);
        if (p == p.parent_path()) break;
    }
    for (const fs::path& p : missing) {
        if (!fs::create_directory(p, ec) && ec) {
            discard();
            throw InputError("--out " + dir_.string() + ": cannot create the output directory (" + ec.message() + ")");
        }
        created_.push_back(p);
    }
    if (!fs::is_directory(parent, ec)) {
        discard();
        throw InputError("--out " + dir_.string() + ": " + parent.string() + " is not a directory");
    }

    remove_stale_in(parent);
    if (exists) remove_old_style_in(target_);

    const std::string leaf = target_.filename().string().substr(0, kLeafInName);
    const std::string tag = random_tag() + "-" + leaf;
    lock_ = parent / (std::string(kLockPrefix) + tag);
    staging_ = parent / (std::string(kStagingPrefix) + tag);
    lock_fd_ = ::open(lock_.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    const bool locked = lock_fd_ >= 0 && ::flock(lock_fd_, LOCK_EX | LOCK_NB) == 0;
    if (!locked || !fs::create_directory(staging_, ec) || ec) {
        const std::string reason = !locked ? system_message(errno) : ec.message();
        discard();
        throw InputError("--out " + dir_.string() + ": the output directory is not writable (" + reason + ")");
    }
}

OutputDirectory::~OutputDirectory() {
    if (!committed_) discard();
}

void OutputDirectory::discard() noexcept {
    std::error_code ec;
    if (!staging_.empty()) fs::remove_all(staging_, ec);
    if (!lock_.empty() && lock_fd_ >= 0) fs::remove(lock_, ec);
    if (lock_fd_ >= 0) ::close(lock_fd_);
    lock_fd_ = -1;
    // Created parents, innermost first, and only while empty (a concurrent run may use them).
    for (auto p = created_.rbegin(); p != created_.rend(); ++p) fs::remove(*p, ec);
    created_.clear();
}

fs::path OutputDirectory::staged(const std::string& name) {
    names_.push_back(name);
    return staging_ / name;
}

void OutputDirectory::commit() {
    throw_if_stopped();
    std::error_code ec;
    // Every byte on disk before the swap: a crash afterwards cannot expose a torn file.
    for (const fs::directory_entry& e : fs::directory_iterator(staging_))
        if (e.is_regular_file()) fsync_path(e.path(), false);
    // Files fretbuzz never writes stay with the directory (hard links: the old set is untouched until the swap).
    if (fs::is_directory(target_, ec)) {
        const std::set<std::string> staged_names(names_.begin(), names_.end());
        for (const fs::directory_entry& e : fs::directory_iterator(target_, ec)) {
            const std::string name = e.path().filename().string();
            if (staged_names.contains(name) || is_run_output_name(name) || is_fretbuzz_folder(name)) continue;
            if (e.is_symlink(ec)) {
                fs::copy_symlink(e.path(), staging_ / name, ec);
            } else if (e.is_regular_file(ec)) {
                if (::link(e.path().c_str(), (staging_ / name).c_str()) != 0 && errno != EEXIST)
                    io_failure("keep", e.path(), errno);
            }
        }
    }
    fsync_path(staging_, true);
    throw_if_stopped();  // last moment at which an interruption leaves the old set as it was

    // The swap: RENAME_EXCHANGE if the directory exists, a plain rename if not; retried
    // when another run creates or removes the directory meanwhile.
    bool swapped = false;
    for (int attempt = 0; attempt < 8 && !swapped; ++attempt) {
        if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, target_.c_str(), RENAME_EXCHANGE) == 0) {
            swapped = true;  // staging_ now holds the old set
        } else if (errno == ENOENT) {
            if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, target_.c_str(), RENAME_NOREPLACE) == 0) {
                swapped = true;
            } else if (errno != EEXIST && errno != ENOTEMPTY) {
                io_failure("move the results into", target_, errno);
            }
        } else if (errno == EINVAL || errno == ENOSYS || errno == EOPNOTSUPP) {
            // No RENAME_EXCHANGE here (some network file systems): move the old set aside
            // first; a reader then briefly finds no directory, never a mix.
            const fs::path aside = staging_.string() + "-old";
            const bool had_old = ::rename(target_.c_str(), aside.c_str()) == 0;
            if (!had_old && errno != ENOENT) io_failure("replace", target_, errno);
            if (::rename(staging_.c_str(), target_.c_str()) != 0) {
                const int error = errno;
                if (had_old) ::rename(aside.c_str(), target_.c_str());
                io_failure("move the results into", target_, error);
            }
            if (had_old) fs::remove_all(aside, ec);
            swapped = true;
        } else {
            io_failure("move the results into", target_, errno);
        }
    }
    if (!swapped) throw std::runtime_error("cannot move the results into " + target_.string() + ": it keeps changing");
    committed_ = true;
    fs::remove_all(staging_, ec);  // the old set (or nothing)
    fs::remove(lock_, ec);
    ::close(lock_fd_);
    lock_fd_ = -1;
    fsync_path(target_.parent_path(), true);
}

}  // namespace fretbuzz
