#include "CsvFile.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "../FileDescriptor.hpp"
#include "fretbuzz/output/CsvWriters.hpp"

namespace fretbuzz {

namespace {
// Numbers per block: big enough that hand-overs are rare (tens per simulated second at
// audio rates), small enough that the two blocks and their text stay in the cache and
// their pages are few (every fresh page costs a fault: at 2^16 numbers the blocks and
// their growing text cost more faults than the whole stepping's memory).
constexpr std::size_t kBlockValues = std::size_t{1} << 14;
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
        filling_ = std::make_unique_for_overwrite<double[]>(block_values_);
        pending_ = std::make_unique_for_overwrite<double[]>(block_values_);
        text_.reserve(block_values_ * 24);  // a shortest round-trip double and its comma
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
    // A few numbers: copied one by one into the block (a range insert calls memmove per row).
    double* to = filling_.get() + filled_;
    for (std::size_t k = 0; k < width_; ++k) to[k] = values[k];
    filled_ += width_;
    if (filled_ == block_values_) hand_over();
}

void CsvFile::hand_over() {
    // The thread starts with the first full block: a short run's rows fit in one and are
    // written at close, without the cost of starting a thread for them.
    if (!thread_.joinable()) thread_ = std::thread([this] { work(); });
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [this] { return pending_values_ == 0 || failure_; });
    if (failure_) std::rethrow_exception(failure_);
    std::swap(filling_, pending_);
    pending_values_ = std::exchange(filled_, 0);
    lock.unlock();
    changed_.notify_all();
}

void CsvFile::close() {
    if (!thread_.joinable()) {
        write_block(std::span<const double>(filling_.get(), std::exchange(filled_, 0)));
        start_tail_writeback();
    } else {
        if (filled_ > 0) hand_over();
        {
            const std::lock_guard lock(mutex_);
            stopping_ = true;
        }
        changed_.notify_all();
        thread_.join();
        if (failure_) std::rethrow_exception(failure_);
    }
    const int fd = std::exchange(fd_, -1);
    if (::close(fd) != 0) write_failure(path_, errno);
}

void CsvFile::work() {
    std::unique_lock lock(mutex_);
    while (true) {
        changed_.wait(lock, [this] { return pending_values_ > 0 || stopping_; });
        if (pending_values_ == 0) {  // stopping, and nothing left
            start_tail_writeback();
            return;
        }
        lock.unlock();
        std::exception_ptr failure;
        try {
            write_block(std::span<const double>(pending_.get(), pending_values_));
        } catch (...) {
            failure = std::current_exception();
        }
        lock.lock();
        pending_values_ = 0;
        if (failure) failure_ = failure;
        changed_.notify_all();
        if (failure_) return;  // the run learns of it at its next hand-over or at close
    }
}

void CsvFile::write_block(std::span<const double> block) {
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

void CsvFile::start_tail_writeback() {
    // Only a hint, as write_block's: the fsync at commit reports any failure.
    if (written_ > writeback_from_) (void)::sync_file_range(fd_, writeback_from_, 0, SYNC_FILE_RANGE_WRITE);
}

void CsvFile::write_all(const char* data, std::size_t size) {
    if (const int error = write_fully(fd_, data, size); error != 0) write_failure(path_, error);
    written_ += static_cast<long long>(size);
}

}  // namespace fretbuzz
