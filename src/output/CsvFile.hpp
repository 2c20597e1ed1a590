#pragma once
// A CSV file of numeric rows, formatted and written by a thread of its own. At audio
// rates the CSV outputs take 480 000 rows per simulated second: formatting them
// (shortest round-trip decimals) and handing them to the kernel cost more than the
// stepping, so the run only copies each row into a block and goes on; the thread formats
// full blocks and writes them while the next block fills. The bytes are those of formatting
// the rows in order on the run's thread.
#include <condition_variable>
#include <exception>
#include <filesystem>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <thread>

namespace fretbuzz {

class CsvFile {
public:
    // Creates (truncates) the file and writes `header` (its lines, with their '\n');
    // every row has `width` numbers. Throws runtime_error naming the file if it cannot.
    CsvFile(const std::filesystem::path& path, const std::string& header, std::size_t width);
    ~CsvFile();  // after a failure: stops the thread and closes the file, whatever it holds
    CsvFile(const CsvFile&) = delete;
    CsvFile& operator=(const CsvFile&) = delete;

    // Appends one row (width() numbers). Throws a write failure the thread met meanwhile.
    void row(std::span<const double> values);
    std::size_t width() const { return width_; }
    // Writes the rest and closes the file; throws runtime_error naming the file (and the
    // system's reason, e.g. "No space left on device") if any write or the close failed.
    void close();

private:
    void hand_over();  // the filled block to the thread (waits while it is busy with the last one)
    void work();       // the thread: formats and writes blocks until told to stop
    void write_block(std::span<const double> block);
    void write_all(const char* data, std::size_t size);
    void start_tail_writeback();  // the bytes since the last hint, once all are written

    std::filesystem::path path_;
    std::size_t width_;
    std::size_t block_values_;
    int fd_ = -1;
    // Left uninitialised: only what is filled is read, and clearing both blocks up front
    // touched every page of them (most of a short run's CSV cost).
    std::unique_ptr<double[]> filling_;  // the run's block (a whole block's room, filled_ numbers used)
    std::unique_ptr<double[]> pending_;  // the thread's block (pending_values_ numbers; 0 when it is free)
    std::size_t filled_ = 0, pending_values_ = 0;
    std::string text_;             // the thread's formatted block
    long long written_ = 0, writeback_from_ = 0;
    bool stopping_ = false;
    std::exception_ptr failure_;
    std::mutex mutex_;
    std::condition_variable changed_;
    std::thread thread_;
};

}  // namespace fretbuzz
