#include "Hdf5Objects.hpp"

#include <fcntl.h>

#include <stdexcept>
#include <utility>

namespace fretbuzz::hdf5 {

namespace {

// Level 1: on shuffled contact-map columns it compresses almost as well as higher levels
// (the bytes are mostly runs of zeros) at a fraction of the time.
constexpr unsigned kDeflateLevel = 1;

hid_t check(hid_t id, const std::string& what) {
    if (id < 0) throw std::runtime_error("HDF5: cannot " + what);
    return id;
}

void check_status(herr_t status, const std::string& what) {
    if (status < 0) throw std::runtime_error("HDF5: cannot " + what);
}

Handle simple_space(std::span<const hsize_t> dims, std::span<const hsize_t> max_dims = {}) {
    return Handle(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), max_dims.empty() ? nullptr : max_dims.data()),
                  H5Sclose, "create a dataspace");
}

Handle scalar_space() { return Handle(H5Screate(H5S_SCALAR), H5Sclose, "create a scalar dataspace"); }

Handle utf8_string_type() {
    Handle type(H5Tcopy(H5T_C_S1), H5Tclose, "copy the string type");
    check_status(H5Tset_size(type.get(), H5T_VARIABLE), "make a variable-length string type");
    check_status(H5Tset_cset(type.get(), H5T_CSET_UTF8), "set the UTF-8 character set");
    return type;
}

// Every write goes through these transfer properties. HDF5's default conversion buffer is
// 1 MiB, allocated zero-filled for each write that converts (variable-length strings,
// doubles stored as float32 or int64): past glibc's mmap threshold, so every such write
// mapped and faulted in fresh pages, costing more than the data. 64 KiB holds a chunk of
// the contact map; larger selections are converted in strips of that size.
hid_t transfer_properties() {
    // Made once and kept for the process (never closed: HDF5 is not shut down at exit).
    static const hid_t properties = [] {
        const hid_t id = check(H5Pcreate(H5P_DATASET_XFER), "create transfer properties");
        check_status(H5Pset_buffer(id, std::size_t{64} << 10, nullptr, nullptr), "set the conversion buffer size");
        return id;
    }();
    return properties;
}

void write_attribute_raw(hid_t object, const std::string& name, hid_t type, const void* value) {
    const Handle space = scalar_space();
    const Handle attribute(H5Acreate2(object, name.c_str(), type, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
                           "create attribute " + name);
    check_status(H5Awrite(attribute.get(), type, value), "write attribute " + name);
}

}  // namespace

Handle::Handle(hid_t id, Closer closer, const std::string& what) : id_(check(id, what)), closer_(closer) {}

Handle& Handle::operator=(Handle&& other) noexcept {
    if (this != &other) {
        reset();
        id_ = std::exchange(other.id_, -1);
        closer_ = other.closer_;
    }
    return *this;
}

void Handle::reset() {
    if (id_ >= 0 && closer_ != nullptr) closer_(id_);
    id_ = -1;
}

void write_attribute_at(hid_t parent, const std::string& path, const std::string& name, const std::string& value) {
    if (H5Lexists(parent, path.c_str(), H5P_DEFAULT) <= 0) return;
    const Handle object(H5Oopen(parent, path.c_str(), H5P_DEFAULT), H5Oclose, "open " + path);
    write_attribute(object.get(), name, value);
}

void Handle::close(const std::string& what) {
    if (id_ < 0 || closer_ == nullptr) return;
    const herr_t status = closer_(std::exchange(id_, -1));
    check_status(status, what);
}

void silence_error_printing() {
    // No clean-up at exit: after a failed close (a full disk) HDF5's own shutdown would
    // touch the half-closed file and crash. Fails harmlessly once the library is running.
    static const bool once = (H5dont_atexit(), true);
    (void)once;
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

Handle create_file(const std::string& path) {
    const Handle access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, "create file access properties");
    check_status(H5Pset_libver_bounds(access.get(), H5F_LIBVER_V110, H5F_LIBVER_LATEST), "set the format bounds");
    return Handle(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, access.get()), H5Fclose, "create " + path);
}

void flush_file(hid_t file, const std::string& path) {
    check_status(H5Fflush(file, H5F_SCOPE_LOCAL), "write " + path);
}

void start_writeback(hid_t file) {
    void* handle = nullptr;
    // The default (sec2) driver's handle is the file descriptor. Only a hint: the fsync
    // before the results are moved into place reports any failure.
    if (H5Fget_vfd_handle(file, H5P_DEFAULT, &handle) >= 0 && handle != nullptr)
        (void)::sync_file_range(*static_cast<int*>(handle), 0, 0, SYNC_FILE_RANGE_WRITE);
}

Handle create_group(hid_t parent, const std::string& name) {
    return Handle(H5Gcreate2(parent, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
                  "create group " + name);
}

void write_array(hid_t parent, const std::string& name, std::span<const double> values) {
    const hsize_t dims[] = {values.size()};
    const Handle space = simple_space(dims);
    const Handle dataset(H5Dcreate2(parent, name.c_str(), H5T_IEEE_F64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                         H5Dclose, "create dataset " + name);
    check_status(H5Dwrite(dataset.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, transfer_properties(), values.data()),
                 "write dataset " + name);
}

void write_array(hid_t parent, const std::string& name, std::span<const long long> values) {
    const hsize_t dims[] = {values.size()};
    const Handle space = simple_space(dims);
    const Handle dataset(H5Dcreate2(parent, name.c_str(), H5T_STD_I64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                         H5Dclose, "create dataset " + name);
    check_status(H5Dwrite(dataset.get(), H5T_NATIVE_LLONG, H5S_ALL, H5S_ALL, transfer_properties(), values.data()),
                 "write dataset " + name);
}

void write_string(hid_t parent, const std::string& name, const std::string& text) {
    const Handle type = utf8_string_type();
    const Handle space = scalar_space();
    const Handle dataset(H5Dcreate2(parent, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                         H5Dclose, "create dataset " + name);
    const char* data = text.c_str();
    check_status(H5Dwrite(dataset.get(), type.get(), H5S_ALL, H5S_ALL, transfer_properties(), &data), "write dataset " + name);
}

void write_strings(hid_t parent, const std::string& name, const std::vector<std::string>& texts) {
    const Handle type = utf8_string_type();
    const hsize_t dims[] = {texts.size()};
    const Handle space = simple_space(dims);
    const Handle dataset(H5Dcreate2(parent, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                         H5Dclose, "create dataset " + name);
    std::vector<const char*> data;
    for (const std::string& text : texts) data.push_back(text.c_str());
    if (!data.empty())
        check_status(H5Dwrite(dataset.get(), type.get(), H5S_ALL, H5S_ALL, transfer_properties(), data.data()),
                     "write dataset " + name);
}

void write_attribute(hid_t object, const std::string& name, double value) {
    write_attribute_raw(object, name, H5T_NATIVE_DOUBLE, &value);
}

void write_attribute(hid_t object, const std::string& name, long long value) {
    write_attribute_raw(object, name, H5T_NATIVE_LLONG, &value);
}

void write_attribute(hid_t object, const std::string& name, const std::string& value) {
    const Handle type = utf8_string_type();
    const char* data = value.c_str();
    write_attribute_raw(object, name, type.get(), &data);
}

GrowingDataset::GrowingDataset(hid_t parent, const std::string& name, std::size_t width, std::size_t chunk_rows,
                               Storage storage, bool compress)
    : width_(width), row_width_(width == 0 ? 1 : width), chunk_rows_(chunk_rows) {
    const int rank = width == 0 ? 1 : 2;
    const hsize_t dims[] = {0, width};
    const hsize_t max_dims[] = {H5S_UNLIMITED, width};
    const hsize_t chunk[] = {chunk_rows, width};
    const Handle space = simple_space(std::span(dims, static_cast<std::size_t>(rank)),
                                      std::span(max_dims, static_cast<std::size_t>(rank)));
    const Handle properties(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, "create dataset properties");
    check_status(H5Pset_chunk(properties.get(), rank, chunk), "set the chunk size of " + name);
    // Every element is written before the file closes: filling chunks first is wasted work.
    check_status(H5Pset_fill_time(properties.get(), H5D_FILL_TIME_NEVER), "set the fill time of " + name);
    if (compress && H5Zfilter_avail(H5Z_FILTER_DEFLATE) > 0) {
        // Shuffle first: sparse maps of mostly zero floats then compress to almost nothing.
        check_status(H5Pset_shuffle(properties.get()), "enable shuffling for " + name);
        check_status(H5Pset_deflate(properties.get(), kDeflateLevel), "enable compression for " + name);
    }
    const hid_t file_type = storage == Storage::float32 ? H5T_IEEE_F32LE
                            : storage == Storage::int64 ? H5T_STD_I64LE
                                                        : H5T_IEEE_F64LE;
    dataset_ = Handle(H5Dcreate2(parent, name.c_str(), file_type, space.get(), H5P_DEFAULT, properties.get(), H5P_DEFAULT),
                      H5Dclose, "create dataset " + name);
    buffer_.reserve(chunk_rows_ * row_width_);
    // Whole chunks of doubles stored as doubles, uncompressed, go to the file as they are:
    // no pass through HDF5's chunk cache (which allocated and cleared each chunk first).
    direct_ = storage == Storage::float64 && !compress && H5Tequal(H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE) > 0;
}

void GrowingDataset::append(std::span<const double> row) {
    if (row.size() != row_width_) throw std::logic_error("GrowingDataset: row of the wrong width");
    for (const double v : row) buffer_.push_back(v);  // a few numbers: no call to memmove per row
    if (pending_rows() == chunk_rows_) flush();
}

namespace {
// Rows [first, first + rows) of a dataset of `width` numbers per row (0: 1-D) from `values`.
void write_rows(hid_t dataset, std::size_t width, bool whole_chunk, std::size_t first, std::size_t rows,
                const std::vector<double>& values) {
    // Writes of rows can fail on a full disk: the message names the file (looked up only then).
    const auto checked = [dataset](herr_t status, const char* what) {
        if (status >= 0) return;
        const ssize_t size = H5Fget_name(dataset, nullptr, 0);
        std::string file(size > 0 ? static_cast<std::size_t>(size) : 0, '\0');
        if (size > 0) H5Fget_name(dataset, file.data(), file.size() + 1);
        throw std::runtime_error("cannot write " + file + ": HDF5 could not " + what);
    };
    const int rank = width == 0 ? 1 : 2;
    const auto rank_size = static_cast<std::size_t>(rank);
    const hsize_t new_dims[] = {first + rows, width};
    checked(H5Dset_extent(dataset, new_dims), "extend a dataset");
    if (whole_chunk) {
        const hsize_t offset[] = {first, 0};
        checked(H5Dwrite_chunk(dataset, transfer_properties(), 0, offset, values.size() * sizeof(double), values.data()),
                "write a chunk of a dataset");
        return;
    }
    const Handle file_space(H5Dget_space(dataset), H5Sclose, "get a dataset's space");
    const hsize_t start[] = {first, 0};
    const hsize_t count[] = {rows, width};
    checked(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start, nullptr, count, nullptr),
            "select rows of a dataset");
    const Handle memory_space = simple_space(std::span(count, rank_size));
    checked(H5Dwrite(dataset, H5T_NATIVE_DOUBLE, memory_space.get(), file_space.get(), transfer_properties(),
                     values.data()),
            "write rows of a dataset");
}

}  // namespace

void GrowingDataset::flush() {
    const std::size_t rows = pending_rows();
    if (rows == 0) return;
    const bool whole_chunk = direct_ && rows == chunk_rows_ && written_ % chunk_rows_ == 0;
    const std::size_t first = written_;
    written_ += rows;
    if (queue_ == nullptr) {
        write_rows(dataset_.get(), width_, whole_chunk, first, rows, buffer_);
        buffer_.clear();
        return;
    }
    std::vector<double> values = std::exchange(buffer_, {});
    buffer_.reserve(chunk_rows_ * row_width_);
    queue_->post([dataset = dataset_.get(), width = width_, whole_chunk, first, rows, values = std::move(values)] {
        write_rows(dataset, width, whole_chunk, first, rows, values);
    });
}

Handle open_file_for_reading(const std::string& path) {
    return Handle(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose, "open " + path);
}

std::string read_string(hid_t parent, const std::string& name) {
    const Handle dataset(H5Dopen2(parent, name.c_str(), H5P_DEFAULT), H5Dclose, "open dataset " + name);
    const Handle type(H5Dget_type(dataset.get()), H5Tclose, "get the type of " + name);
    if (H5Tget_class(type.get()) != H5T_STRING) throw std::runtime_error("HDF5: " + name + " is not a string");
    if (H5Tis_variable_str(type.get()) > 0) {
        const Handle memory_type = utf8_string_type();
        char* data = nullptr;
        check_status(H5Dread(dataset.get(), memory_type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, &data), "read " + name);
        std::string text = data != nullptr ? data : "";
        H5free_memory(data);
        return text;
    }
    std::string text(H5Tget_size(type.get()), '\0');
    check_status(H5Dread(dataset.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, text.data()), "read " + name);
    return text.substr(0, text.find('\0'));
}

}  // namespace fretbuzz::hdf5
