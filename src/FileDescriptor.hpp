#pragma once
// A file descriptor closed on every way out of a scope; close() closes it at once where the
// caller needs the result (a write's last error can come from close).
#include <unistd.h>

#include <utility>

namespace fretbuzz {

class FileDescriptor {
public:
    explicit FileDescriptor(int fd) : fd_(fd) {}
    ~FileDescriptor() {
        if (fd_ >= 0) ::close(fd_);
    }
    FileDescriptor(const FileDescriptor&) = delete;
    FileDescriptor& operator=(const FileDescriptor&) = delete;
    int get() const { return fd_; }
    int close() { return ::close(std::exchange(fd_, -1)); }

private:
    int fd_;
};

}  // namespace fretbuzz
