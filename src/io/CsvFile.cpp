#include "CsvFile.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "fretbuzz/io/CsvWriters.hpp"

namespace fretbuzz {

namespace {
// Numbers per block: big enough that hand-overs are rare (a few per simulated second at
// audio rates), small enough that the two blocks stay in the cache.
constexpr std::size_t kBlockValues = std::size_t{1} << 16;
// Once this much is written, the kernel is asked to start putting it on disk, so that
// the fsync before the results are moved into place finds little left to wait for.
constexpr long long kWritebackBytes = 8LL << 20;

[[noreturn]] void write_failure(const std::filesystem::path& path, int error) {
    throw std::runtime_error("cannot write " + path.string() + ": " + std::strerror(error));
}
}  // namespace

CsvFile::CsvFile(const std::filesystem::path& path, const std::string& header, std::size_t width)
    : path_(path), width_(std::max<std::size_t>(1, width)), block_values_(std::max(width_, kBlockValues / width_ * width_)) {
    fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd_ < 0) write_failure(path_, errno);
    try {
        write_all(header.data(), header.size());
        filling_.reserve(block_values_);
        pending_.reserve(block_values_);
        thread_ = std::thread([this] { work(); });
    } catch (...) {
        ::close(fd_);
        throw;
    }
}

CsvFile::~CsvFile() {
    if (thread_.joinable()) {
        {
            const std::lock_guard lock(mutex_);
            stopping_ = true;
        }
        changed_.notify_all();
        thread_.join();
    }
    if (fd_ >= 0) ::close(fd_);
}

void CsvFile::row(std::span<const double> values) {
    if (values.size() != width_) throw std::logic_error("CsvFile: a row of the wrong width");
    filling_.insert(filling_.end(), values.begin(), values.end());
    if (filling_.size() >= block_values_) hand_over();
}

void CsvFile::hand_over() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [this] { return pending_.empty() || failure_; });
    if (failure_) std::rethrow_exception(failure_);
    std::swap(filling_, pending_);
    filling_.clear();
    lock.unlock();
    changed_.notify_all();
}

void CsvFile::close() {
    if (!filling_.empty()) hand_over();
    {
        const std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    changed_.notify_all();
    thread_.join();
    if (failure_) std::rethrow_exception(failure_);
    const int fd = std::exchange(fd_, -1);
    if (::close(fd) != 0) write_failure(path_, errno);
}

void CsvFile::work() {
    std::unique_lock lock(mutex_);
    while (true) {
        changed_.wait(lock, [this] { return !pending_.empty() || stopping_; });
        if (pending_.empty()) {  // stopping, and nothing left: start writeback of the tail too
            if (written_ > writeback_from_) (void)::sync_file_range(fd_, writeback_from_, 0, SYNC_FILE_RANGE_WRITE);
            return;
        }
        lock.unlock();
        std::exception_ptr failure;
        try {
            write_block(pending_);
        } catch (...) {
            failure = std::current_exception();
        }
        lock.lock();
        pending_.clear();
        if (failure) failure_ = failure;
        changed_.notify_all();
        if (failure_) return;  // the run learns of it at its next hand-over or at close
    }
}

void CsvFile::write_block(const std::vector<double>& block) {
    text_.clear();
    for (std::size_t start = 0; start < block.size(); start += width_) {
        for (std::size_t k = 0; k < width_; ++k) {
            if (k > 0) text_ += ',';
            append_number(text_, block[start + k]);
        }
        text_ += '\n';
    }
    write_all(text_.data(), text_.size());
    if (written_ - writeback_from_ >= kWritebackBytes) {
        // Only a hint (the result is ignored): the fsync at commit reports any failure.
        (void)::sync_file_range(fd_, writeback_from_, written_ - writeback_from_, SYNC_FILE_RANGE_WRITE);
        writeback_from_ = written_;
    }
}

void CsvFile::write_all(const char* data, std::size_t size) {
    while (size > 0) {
        const ssize_t n = ::write(fd_, data, size);
        if (n <= 0) {
            if (n < 0 && errno == EINTR) continue;
            write_failure(path_, n < 0 ? errno : EIO);
        }
        data += n;
        size -= static_cast<std::size_t>(n);
        written_ += n;
    }
}

}  // namespace fretbuzz
