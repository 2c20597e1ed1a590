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
#include <limits>
#include <random>
#include <set>
#include <stdexcept>

#include "IoFailure.hpp"
#include "fretbuzz/Error.hpp"

namespace fretbuzz {

namespace fs = std::filesystem;

namespace {

constexpr std::string_view kStagingPrefix = ".fretbuzz-staging-";
constexpr std::string_view kLockPrefix = ".fretbuzz-lock-";
constexpr std::string_view kOldStagingPrefix = ".fretbuzz-partial-";  // inside --out, before staging moved beside it
constexpr std::size_t kLeafInName = 100;  // keeps the staging name under NAME_MAX
constexpr unsigned kTagRange = 1000000;   // the random number in a staging folder's name
constexpr std::string_view kAsideSuffix = "-old";  // the old set, where folders cannot be swapped

std::string system_message(int error) { return std::strerror(error); }

// The longest name of a file a run or its report writes (besides the WAV files, checked as
// they are named): what the output directory must have room for.
constexpr std::string_view kLongestOutputName = "signal_all_points.png";

// The limits of the file system that holds `path` (or would: its nearest existing folder).
using NameLimits = OutputDirectory::NameLimits;
NameLimits limits_at(const fs::path& path) {
    std::error_code ec;
    fs::path existing = path;
    while (!existing.empty() && existing != existing.root_path() && !fs::exists(existing, ec))
        existing = existing.parent_path();
    const long name = existing.empty() ? -1 : ::pathconf(existing.c_str(), _PC_NAME_MAX);
    const long path_max = existing.empty() ? -1 : ::pathconf(existing.c_str(), _PC_PATH_MAX);
    return {name > 0 ? static_cast<std::size_t>(name) : NAME_MAX,
            static_cast<std::size_t>(path_max > 0 ? path_max : PATH_MAX) - 1};
}

std::string shortened(const std::string& text) { return text.size() <= 64 ? text : text.substr(0, 64) + "..."; }

// Names are limited by the file system: a run that could not write its last file is refused
// before it computes anything, not after (ENAMETOOLONG from deep inside a writer).
void check_name_lengths(const std::string& label, const fs::path& dir, const NameLimits& limits) {
    for (const fs::path& part : dir)
        if (part.string().size() > limits.name)
            throw InputError(label + ": the name '" + part.string().substr(0, 32) + "...' is " +
                             std::to_string(part.string().size()) + " bytes long; names there may have at most " +
                             std::to_string(limits.name) + " bytes");
}

void check_path_length(const std::string& label, const fs::path& path, const NameLimits& limits) {
    if (path.string().size() > limits.path)
        throw InputError(label + ": too long: a file of the run could be " + path.string().substr(0, 32) +
                         "..." + path.filename().string() + ", " + std::to_string(path.string().size()) +
                         " bytes; paths there may have at most " + std::to_string(limits.path) + " bytes");
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

std::string tag_of(pid_t pid, unsigned random) { return std::to_string(pid) + "-" + std::to_string(random); }

std::string random_tag() {
    std::random_device device;
    return tag_of(::getpid(), device() % kTagRange);
}

// The longest tag of any run: its process id and random number at their widest. Names are
// checked with it, so that whether a --out is accepted does not depend on the process id.
std::string widest_tag() { return tag_of(std::numeric_limits<pid_t>::max(), kTagRange - 1); }

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
        "contactogram.png", "snapshots.png", "animation.gif",       "animation.mp4",
        // a set-up study's files
        "buzz_map.csv",    "buzz_map.html", "map.json", "compare.csv", "advice.json", "advice.txt",
        // a run of strings on a bridge
        "strings.csv", "bridge.wav", "bridge.ogg", "case.toml", "strings_energy.png"};
    if (fixed.contains(name)) return true;
    return name.ends_with(".wav") && (name.starts_with("audio") || name.starts_with("velocity") ||
                                      name.starts_with("note-") || name.starts_with("pickup_"));
}

std::size_t remove_stale_staging(const fs::path& dir) {
    std::error_code ec;
    const fs::path absolute = fs::absolute(dir, ec).lexically_normal();
    const fs::path target = absolute.has_filename() ? absolute : absolute.parent_path();
    std::size_t removed = remove_stale_in(target.parent_path());
    if (fs::is_directory(target, ec)) removed += remove_stale_in(target) + remove_old_style_in(target);
    return removed;
}

namespace {
// Why an entry of an existing output directory stops the run ("" if it does not): fretbuzz
// replaces the directory as a whole and never deletes what it did not write. Its own files are
// replaced, other regular files are kept (hard-linked into the new set), links too (copied),
// unless a link has the name of a file the run writes (the file would take its place).
std::string foreign_entry(const fs::directory_entry& e) {
    const std::string name = e.path().filename().string();
    if (is_fretbuzz_folder(name)) return {};
    std::error_code ec;
    const fs::file_status status = e.symlink_status(ec);
    if (ec) return "cannot be examined (" + ec.message() + ")";
    if (fs::is_regular_file(status)) return {};
    if (fs::is_symlink(status))
        return is_run_output_name(name) ? "is a symbolic link with the name of a file fretbuzz writes" : "";
    if (fs::is_directory(status)) return "is a folder that fretbuzz did not write";
    if (fs::is_fifo(status)) return "is a FIFO";
    if (fs::is_socket(status)) return "is a socket";
    if (fs::is_block_file(status) || fs::is_character_file(status)) return "is a device node";
    return "is a special file";
}

[[noreturn]] void refuse_entry(const std::string& label, const fs::path& entry, const std::string& why) {
    throw InputError(label + ": " + entry.string() + " " + why +
                     "; the output directory is replaced as a whole and fretbuzz never deletes what it did not write: "
                     "move it away, or give a new folder, an empty one or an earlier output directory");
}
}  // namespace

OutputDirectory::OutputDirectory(const fs::path& dir, const std::string& what)
    : dir_(dir), label_(what + " " + shortened(dir.string())) {
    if (dir.empty()) throw InputError(what + ": the output directory name is empty");
    const std::string& given = label_;
    std::error_code ec;
    // A symbolic link stands for the folder it points to (canonical() below): that folder gets
    // the results, the link stays as it is. A link to nothing is refused, not replaced.
    const fs::file_status status = fs::status(dir_, ec);
    if (fs::is_symlink(fs::symlink_status(dir_, ec)) && !fs::exists(status))
        throw InputError(given + ": is a symbolic link to " + fs::read_symlink(dir_, ec).string() +
                         ", which does not exist; create that folder or give another --out");
    if (fs::exists(status) && !fs::is_directory(status))
        throw InputError(given + ": exists and is not a directory");
    const bool exists = fs::exists(status);
    target_ = exists ? fs::canonical(dir_, ec) : fs::absolute(dir_, ec).lexically_normal();
    if (!target_.has_filename()) target_ = target_.parent_path();
    if (ec || target_ == target_.root_path())
        throw InputError(given + ": cannot be used as an output directory");
    const fs::path cwd = fs::current_path(ec);
    if (exists && !ec && (cwd == target_ || cwd.string().starts_with(target_.string() + "/")))
        throw InputError(given +
                         ": is the current directory or one of its parents; the output directory is replaced as a "
                         "whole, give a folder of its own");

    // Every name the run will use fits the file system's limits.
    const fs::path parent = target_.parent_path();
    limits_ = limits_at(target_);
    check_name_lengths(given, target_, limits_);
    const std::string leaf = target_.filename().string().substr(0, kLeafInName);
    const std::string tag = random_tag() + "-" + leaf;
    lock_ = parent / (std::string(kLockPrefix) + tag);
    staging_ = parent / (std::string(kStagingPrefix) + tag);
    widest_staging_ = parent / (std::string(kStagingPrefix) + widest_tag() + "-" + leaf);
    check_name_lengths(given, widest_staging_, limits_);
    check_path_length(given, widest_staging_ / kLongestOutputName, limits_);
    check_path_length(given, widest_staging_.string() + std::string(kAsideSuffix), limits_);
    check_path_length(given, target_ / kLongestOutputName, limits_);

    if (exists) {
        // (Unlisted, its content could not be kept: refused.)
        fs::directory_iterator entries(target_, ec);
        if (ec) throw InputError(given + ": cannot be read (" + ec.message() + "); its content would be lost");
        for (const fs::directory_entry& e : entries)
            if (const std::string why = foreign_entry(e); !why.empty()) refuse_entry(given, e.path(), why);
        struct stat st {};
        if (::stat(target_.c_str(), &st) != 0) io_failure("examine", target_, errno);
        kept_ = Kept{st.st_mode & 07777, st.st_uid, st.st_gid};
    }

    // Missing parents (a/b for --out a/b/c), outermost first, to remove if the run fails.
    std::vector<fs::path> missing;
    for (fs::path p = parent; !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
        missing.insert(missing.begin(), p);
        if (p == p.parent_path()) break;
    }
    for (const fs::path& p : missing) {
        if (!fs::create_directory(p, ec) && ec) {
            discard();
            throw InputError(given + ": cannot create the output directory (" + ec.message() + ")");
        }
        created_.push_back(p);
    }
    if (!fs::is_directory(parent, ec)) {
        discard();
        throw InputError(given + ": " + parent.string() + " is not a directory");
    }

    remove_stale_in(parent);
    if (exists) remove_old_style_in(target_);

    lock_fd_ = ::open(lock_.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    const bool locked = lock_fd_ >= 0 && ::flock(lock_fd_, LOCK_EX | LOCK_NB) == 0;
    if (!locked || !fs::create_directory(staging_, ec) || ec) {
        const std::string reason = !locked ? system_message(errno) : ec.message();
        discard();
        throw InputError(given + ": the output directory is not writable (" + reason + ")");
    }
    if (kept_) keep_owner(given);
}

void OutputDirectory::keep_owner(const std::string& given) {
    // The new set takes the old folder's place: it gets its owner and group now (a user who
    // cannot give them is told before the run), its mode at commit (writable meanwhile).
    struct stat st {};
    const bool owned = ::stat(staging_.c_str(), &st) == 0 && st.st_uid == kept_->uid && st.st_gid == kept_->gid;
    if (!owned && ::chown(staging_.c_str(), kept_->uid, kept_->gid) != 0) {
        const int error = errno;
        discard();
        throw InputError(given + ": belongs to user " + std::to_string(kept_->uid) + " and group " +
                         std::to_string(kept_->gid) + ", which this user cannot give the folder that replaces it (" +
                         system_message(error) + "); run as its owner or give a folder of your own");
    }
    if (::chmod(staging_.c_str(), kept_->mode | S_IRWXU) != 0) {
        const int error = errno;
        discard();
        io_failure("set the mode of", staging_, error);
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
    // A name with folders (bridges/taraf-string.toml) gets them inside the staging folder.
    const fs::path relative = fs::path(name).lexically_normal();
    if (name.empty() || relative.is_absolute() || *relative.begin() == "..")
        throw InputError(label_ + ": " + name + " is not a name inside the output directory");
    for (const fs::path& part : relative)
        if (part.string().size() > limits_.name)
            throw InputError(label_ + ": the file name " + part.string().substr(0, 32) + "... is " +
                             std::to_string(part.string().size()) + " bytes long; names there may have at most " +
                             std::to_string(limits_.name) + " bytes");
    check_path_length(label_, widest_staging_ / relative, limits_);
    check_path_length(label_, target_ / relative, limits_);
    names_.push_back(relative.begin()->string());
    if (relative.has_parent_path()) {
        std::error_code ec;
        fs::create_directories(staging_ / relative.parent_path(), ec);
        if (ec) io_failure("create", staging_ / relative.parent_path(), ec.value());
    }
    return staging_ / relative;
}

void OutputDirectory::commit() {
    throw_if_stopped();
    std::error_code ec;
    // Every byte on disk before the swap: a crash afterwards cannot expose a torn file.
    for (const fs::directory_entry& e : fs::recursive_directory_iterator(staging_))
        if (e.is_regular_file() || e.is_directory()) fsync_path(e.path(), e.is_directory());
    // Files fretbuzz never writes stay with the directory (hard links: the old set is untouched until the swap).
    if (fs::is_directory(target_, ec)) {
        const std::set<std::string> staged_names(names_.begin(), names_.end());
        for (const fs::directory_entry& e : fs::directory_iterator(target_, ec)) {
            const std::string name = e.path().filename().string();
            if (staged_names.contains(name) || is_fretbuzz_folder(name)) continue;
            // Checked again: something may have appeared since the run started.
            if (const std::string why = foreign_entry(e); !why.empty()) refuse_entry(label_, e.path(), why);
            if (is_run_output_name(name)) continue;
            if (e.is_symlink(ec)) {
                fs::copy_symlink(e.path(), staging_ / name, ec);
            } else if (e.is_regular_file(ec)) {
                if (::link(e.path().c_str(), (staging_ / name).c_str()) != 0 && errno != EEXIST)
                    io_failure("keep", e.path(), errno);
            }
        }
    }
    if (kept_ && ::chmod(staging_.c_str(), kept_->mode) != 0) io_failure("set the mode of", staging_, errno);
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
            const fs::path aside = staging_.string() + std::string(kAsideSuffix);
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
