#pragma once
// Thin RAII wrappers over the HDF5 C API, private to the writers: owned handles, one-shot
// writes of arrays, strings and attributes, and datasets that grow by rows as a run goes
// (chunked and extendible, so nothing but one chunk of rows is ever held in memory).
#include <hdf5.h>

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "fretbuzz/run/WriteQueue.hpp"

namespace fretbuzz::hdf5 {

// An HDF5 identifier closed by the matching H5?close when it goes out of scope.
class Handle {
public:
    using Closer = herr_t (*)(hid_t);
    Handle() = default;
    Handle(hid_t id, Closer closer, const std::string& what);  // throws if id < 0
    ~Handle() { reset(); }
    Handle(Handle&& other) noexcept : id_(other.id_), closer_(other.closer_) { other.id_ = -1; }
    Handle& operator=(Handle&& other) noexcept;
    Handle(const Handle&) = delete;
    Handle& operator=(const Handle&) = delete;
    hid_t get() const { return id_; }
    void reset();  // closes, ignoring the status (for unwinding)
    void close(const std::string& what);  // closes; throws naming `what` if HDF5 reports a failure

private:
    hid_t id_ = -1;
    Closer closer_ = nullptr;
};

// Stops HDF5 printing its error stack; failures become exceptions instead.
void silence_error_printing();

Handle create_file(const std::string& path);
// Writes everything the library holds for the file to disk; throws naming path on failure.
void flush_file(hid_t file, const std::string& path);
// Asks the kernel to start writing what is already written to the file to disk, so
// that the fsync at the end finds little left to wait for.
void start_writeback(hid_t file);
Handle create_group(hid_t parent, const std::string& name);

void write_array(hid_t parent, const std::string& name, std::span<const double> values);
void write_array(hid_t parent, const std::string& name, std::span<const long long> values);
void write_string(hid_t parent, const std::string& name, const std::string& text);  // UTF-8, variable length
void write_strings(hid_t parent, const std::string& name, const std::vector<std::string>& texts);  // 1-D, the same
void write_attribute(hid_t object, const std::string& name, double value);
void write_attribute(hid_t object, const std::string& name, long long value);
void write_attribute(hid_t object, const std::string& name, const std::string& value);
// A string attribute on the object at `path` below `parent`, if that object exists.
void write_attribute_at(hid_t parent, const std::string& path, const std::string& name, const std::string& value);

// int64: whole numbers held as doubles in memory (exact below 2^53), stored as integers.
enum class Storage { float64, float32, int64 };

// A dataset of rows of `width` numbers (width 0: a 1-D dataset of scalars) that grows
// one row at a time. Rows are buffered up to one chunk and written chunk by chunk.
class GrowingDataset {
public:
    GrowingDataset() = default;
    GrowingDataset(hid_t parent, const std::string& name, std::size_t width, std::size_t chunk_rows,
                   Storage storage = Storage::float64, bool compress = false);
    void append(std::span<const double> row);
    // One number per row (the signals at audio rates: hundreds of thousands of rows per
    // simulated second): kept inline, without the general row's range insert.
    void append(double value) {
        if (row_width_ != 1) return append(std::span<const double>(&value, 1));
        buffer_.push_back(value);
        if (buffer_.size() == chunk_rows_) flush();
    }
    void flush();
    // From now on full chunks are written by `queue` (which must outlive the dataset's writes;
    // see WriteQueue: HDF5 is not thread-safe).
    void write_through(WriteQueue* queue) { queue_ = queue; }
    void close(const std::string& what) { dataset_.close(what); }
    std::size_t rows() const { return written_ + pending_rows(); }
    std::size_t width() const { return row_width_; }
    hid_t id() const { return dataset_.get(); }

private:
    std::size_t pending_rows() const { return row_width_ == 0 ? 0 : buffer_.size() / row_width_; }

    Handle dataset_;
    std::size_t width_ = 0;      // as declared (0 for 1-D)
    std::size_t row_width_ = 1;  // numbers per row
    std::size_t chunk_rows_ = 1;
    std::size_t written_ = 0;
    bool direct_ = false;  // whole chunks written as they are (see the constructor)
    std::vector<double> buffer_;
    WriteQueue* queue_ = nullptr;
};

}  // namespace fretbuzz::hdf5

namespace fretbuzz::hdf5 {

Handle open_file_for_reading(const std::string& path);
// A scalar string dataset (fixed or variable length).
std::string read_string(hid_t parent, const std::string& name);

}  // namespace fretbuzz::hdf5
