#include "fretbuzz/input/TextFile.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstring>
#include <stdexcept>

#include "../FileDescriptor.hpp"
#include "fretbuzz/Error.hpp"

namespace fretbuzz {

namespace {

std::string size_text(std::size_t bytes) { return std::to_string(bytes >> 20) + " MiB"; }

// A path that names nothing is the user's to mend (InputError, exit 2); a file there that the
// system cannot read (permissions, a failing disk) is not (std::runtime_error, exit 1).
[[noreturn]] void cannot_read(const std::string& what, const std::string& name, int error) {
    if (error == ENOENT || error == ENOTDIR || error == ELOOP)
        throw InputError(what + ": cannot read " + name + ": no such file");
    throw std::runtime_error(what + ": cannot read " + name + " (" + std::strerror(error) + ")");
}

}  // namespace

std::string read_text_file(const std::filesystem::path& path, const std::string& what, std::size_t max_bytes) {
    const std::string name = path.string();
    if (name.size() >= PATH_MAX)
        throw InputError(what + ": the path is longer than " + std::to_string(PATH_MAX - 1) + " bytes");
    for (const std::filesystem::path& part : path)
        if (part.string().size() > NAME_MAX)
            throw InputError(what + ": a name in the path is " + std::to_string(part.string().size()) +
                             " bytes long; names may have at most " + std::to_string(NAME_MAX) + " bytes");
    struct stat info {};
    if (::stat(path.c_str(), &info) != 0) cannot_read(what, name, errno);
    if (!S_ISREG(info.st_mode)) throw InputError(what + ": " + name + " is not a regular file");
    // O_NONBLOCK: should the name become a FIFO after the check, opening it must not hang.
    const FileDescriptor fd(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY));
    if (fd.get() < 0) cannot_read(what, name, errno);
    if (::fstat(fd.get(), &info) != 0 || !S_ISREG(info.st_mode))
        throw InputError(what + ": " + name + " is not a regular file");
    if (static_cast<std::size_t>(info.st_size) > max_bytes)
        throw InputError(what + ": " + name + " is larger than " + size_text(max_bytes));
    std::string text;
    text.resize(static_cast<std::size_t>(info.st_size));
    std::size_t filled = 0;
    while (true) {
        if (filled == text.size()) {  // the file grew meanwhile: read on, up to the limit
            if (text.size() >= max_bytes + 1) break;
            text.resize(std::min(max_bytes + 1, text.size() + 65536));
        }
        const ssize_t n = ::read(fd.get(), text.data() + filled, text.size() - filled);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) cannot_read(what, name, errno);
        if (n == 0) break;
        filled += static_cast<std::size_t>(n);
    }
    if (filled > max_bytes) throw InputError(what + ": " + name + " is larger than " + size_text(max_bytes));
    text.resize(filled);
    return text;
}

}  // namespace fretbuzz
