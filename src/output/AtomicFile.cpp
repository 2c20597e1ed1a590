#include "fretbuzz/output/AtomicFile.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "IoFailure.hpp"
#include "fretbuzz/Error.hpp"

namespace fretbuzz {

namespace fs = std::filesystem;

namespace {

void sync(const fs::path& path, int flags) {
    const int fd = ::open(path.c_str(), flags | O_RDONLY | O_CLOEXEC);
    if (fd < 0) io_failure("open", path, errno);
    const int status = ::fsync(fd);
    const int error = errno;
    ::close(fd);
    // A folder on a file system that cannot sync folders (EINVAL) still holds the rename.
    if (status != 0 && !((flags & O_DIRECTORY) && error == EINVAL)) io_failure("write", path, error);
}

std::string lower(std::string text) {
    std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return text;
}

}  // namespace

AtomicFile::AtomicFile(const fs::path& target, const std::string& what) : target_(target) {
    const std::string name = target.filename().string();
    if (name.empty() || name == "." || name == "..")
        throw InputError(what + " " + target.string() + ": give a file name, not a folder");
    if (target.string().size() >= PATH_MAX)
        throw InputError(what + ": the path is longer than " + std::to_string(PATH_MAX - 1) + " bytes");
    for (const fs::path& part : target)
        if (part.string().size() > NAME_MAX)
            throw InputError(what + ": a name in the path is " + std::to_string(part.string().size()) +
                             " bytes long; names may have at most " + std::to_string(NAME_MAX) + " bytes");
    const fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
    struct stat info {};
    if (::stat(folder.c_str(), &info) != 0 || !S_ISDIR(info.st_mode))
        throw InputError(what + " " + target.string() + ": the folder " + folder.string() + " does not exist");
    mode_t mode = 0666;  // less the umask, as for any new file
    bool keep_mode = false;
    if (::lstat(target.c_str(), &info) == 0) {
        if (S_ISDIR(info.st_mode))
            throw InputError(what + " " + target.string() + " is a folder: give a file name, such as " +
                             (target / "take.wav").string());
        if (!S_ISREG(info.st_mode) && !S_ISLNK(info.st_mode))
            throw InputError(what + " " + target.string() +
                             " is not a regular file (a FIFO, socket or device): it is left alone");
        if (S_ISREG(info.st_mode)) {
            mode = info.st_mode & 07777;
            keep_mode = true;
        }
    }
    // A name of our own beside the target, short enough for the file system, with the target's
    // extension; created exclusively, so no other process writes it. Its length is checked
    // with the process id and the counter at their widest: whether a target is accepted does
    // not depend on them.
    static std::atomic<unsigned> counter{0};
    const std::string given = target.extension().string();
    const std::string extension = given.size() <= 16 ? lower(given) : "";
    const auto name_with = [&](const std::string& stem, auto pid, auto n) {
        return "." + stem + ".tmp-" + std::to_string(pid) + "-" + std::to_string(n) + extension;
    };
    const std::size_t widest =
        name_with("", std::numeric_limits<pid_t>::max(), std::numeric_limits<unsigned>::max()).size();
    const std::string stem = target.stem().string().substr(0, NAME_MAX - widest);
    const fs::path longest =
        folder / name_with(stem, std::numeric_limits<pid_t>::max(), std::numeric_limits<unsigned>::max());
    if (longest.string().size() >= PATH_MAX)
        throw InputError(what + " " + target.string().substr(0, 32) + "...: too long: the file is written first beside it, as " +
                         longest.filename().string() + " (up to " + std::to_string(longest.string().size()) +
                         " bytes); paths may have at most " + std::to_string(PATH_MAX - 1) + " bytes");
    for (int attempt = 0;; ++attempt) {
        temporary_ = folder / name_with(stem, ::getpid(), counter++);
        const int fd = ::open(temporary_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, mode);
        if (fd >= 0) {
            if (keep_mode) (void)::fchmod(fd, mode);  // the umask would otherwise narrow it
            ::close(fd);
            return;
        }
        if (errno != EEXIST || attempt >= 100)
            throw InputError(what + " " + target.string() + ": cannot create a file in " + folder.string() + " (" +
                             std::strerror(errno) + ")");
    }
}

AtomicFile::~AtomicFile() {
    if (!committed_) ::unlink(temporary_.c_str());
}

void AtomicFile::commit() {
    sync(temporary_, 0);
    if (::rename(temporary_.c_str(), target_.c_str()) != 0) io_failure("write", target_, errno);
    committed_ = true;
    sync(target_.has_parent_path() ? target_.parent_path() : fs::path("."), O_DIRECTORY);
}

}  // namespace fretbuzz
