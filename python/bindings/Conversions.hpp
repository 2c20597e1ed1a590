#pragma once
// Python values to C++ and back, for the bindings. Conversions are strict and name the
// field: a string, a list or a bool where a number belongs is a TypeError, never a
// silent 1.0 (True) or a dropped value.
#include <pybind11/numpy.h>

#include <algorithm>
#include <limits>
#include <string>
#include <vector>

#include "fretbuzz/Error.hpp"

namespace fretbuzz::python {

inline pybind11::array_t<double> to_numpy(const std::vector<double>& v) {
    return pybind11::array_t<double>(static_cast<pybind11::ssize_t>(v.size()), v.data());
}

// A read-only copy: `case.frequencies[0] = 1.0` raises instead of changing a copy nobody
// sees; arrays are assigned whole (`case.frequencies = edited`).
inline pybind11::array_t<double> to_read_only_numpy(const std::vector<double>& v) {
    auto array = to_numpy(v);
    array.attr("setflags")(pybind11::arg("write") = false);
    return array;
}

inline std::string type_name(pybind11::handle value) {
    return pybind11::str(pybind11::type::handle_of(value).attr("__name__")).cast<std::string>();
}

// A real number (int, float, NumPy scalar), not a bool. A whole number beyond the range of
// a double (10**400) becomes +-inf, which the case's checks then refuse naming its key and
// range.
inline double to_number(pybind11::handle value, const std::string& name) {
    namespace py = pybind11;
    const bool real = py::isinstance(value, py::module_::import("numbers").attr("Real"));
    if (!real || py::isinstance<py::bool_>(value))
        throw py::type_error(name + ": expected a number (float), got " + type_name(value));
    try {
        return value.cast<double>();
    } catch (const py::cast_error&) {
        PyErr_Clear();
        const int positive = PyObject_RichCompareBool(value.ptr(), py::int_(0).ptr(), Py_GT);
        if (positive < 0) throw py::error_already_set();
        return positive ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity();
    }
}

// A whole number (int, NumPy integer; not a bool, not a float) in [low, high]: TypeError
// for another kind, fretbuzz's InputError for one out of range, each naming the field, its
// range and the value given (a Python int of any size, printed as given).
inline long long to_whole(pybind11::handle value, const std::string& name, long long low, long long high) {
    namespace py = pybind11;
    const std::string range = "a whole number in [" + std::to_string(low) + ", " + std::to_string(high) + "]";
    if (!py::isinstance(value, py::module_::import("numbers").attr("Integral")) || py::isinstance<py::bool_>(value))
        throw py::type_error(name + ": expected " + range + ", got " + type_name(value) + " " +
                             py::repr(value).cast<std::string>());
    const py::int_ n(py::reinterpret_borrow<py::object>(value));
    if (!(py::int_(low) <= n && n <= py::int_(high)))
        throw InputError(name + " = " + py::repr(n).cast<std::string>() + " is out of range: must be " + range);
    return n.cast<long long>();
}

// At most this many entries in a list that names notes (frets, strings): an instrument has a
// few dozen; a longer list asks for the same notes again (or is a mistake).
inline constexpr std::size_t kMaxListEntries = 1024;

// The entries of a list argument (a list, tuple or other sequence; not a str), at most
// kMaxListEntries of them: TypeError or InputError naming `name`.
inline std::vector<pybind11::handle> list_entries(pybind11::handle values, const std::string& name) {
    namespace py = pybind11;
    if (py::isinstance<py::str>(values) || py::isinstance<py::bytes>(values) || !py::isinstance<py::sequence>(values))
        throw py::type_error(name + ": expected a list, got " + type_name(values));
    const py::sequence sequence = py::reinterpret_borrow<py::sequence>(values);
    if (sequence.size() > kMaxListEntries)
        throw InputError(name + ": " + std::to_string(sequence.size()) + " entries; give each one once (at most " +
                         std::to_string(kMaxListEntries) + ")");
    std::vector<py::handle> entries;
    for (py::handle item : sequence) entries.push_back(item);
    return entries;
}

// A list of whole numbers in [low, high], each counted once, in the order first given (a
// repeated fret asks for the same note again): TypeError or InputError naming `name`.
inline std::vector<std::size_t> to_whole_list(pybind11::handle values, const std::string& name, long long low,
                                              long long high) {
    std::vector<std::size_t> out;
    for (pybind11::handle item : list_entries(values, name)) {
        const auto n = static_cast<std::size_t>(to_whole(item, name, low, high));
        if (std::find(out.begin(), out.end(), n) == out.end()) out.push_back(n);
    }
    return out;
}

inline std::string to_text(pybind11::handle value, const std::string& name) {
    if (!pybind11::isinstance<pybind11::str>(value))
        throw pybind11::type_error(name + ": expected a str, got " + type_name(value));
    return value.cast<std::string>();
}

// A list of str, each counted once, in the order first given (TypeError naming `name`).
inline std::vector<std::string> to_text_list(pybind11::handle values, const std::string& name) {
    std::vector<std::string> out;
    for (pybind11::handle item : list_entries(values, name)) {
        std::string text = to_text(item, name + " entry");
        if (std::find(out.begin(), out.end(), text) == out.end()) out.push_back(std::move(text));
    }
    return out;
}

// Any 1-D sequence of real numbers, taken whole.
inline std::vector<double> to_vector(pybind11::handle values, const std::string& name) {
    namespace py = pybind11;
    const std::string expected = name + ": expected a 1-D sequence of numbers";
    if (py::isinstance<py::str>(values) || py::isinstance<py::bytes>(values) || py::isinstance<py::dict>(values))
        throw py::type_error(expected + ", got " + type_name(values));
    py::array array;
    try {
        array = py::module_::import("numpy").attr("asarray")(values);
    } catch (const py::error_already_set&) {
        throw py::type_error(expected + " (not a ragged or nested one)");
    }
    if (array.dtype().kind() == 'O') {
        // Whole numbers beyond a double's range (10**400) come as Python objects: each one
        // as to_number takes it.
        std::vector<double> numbers;
        if (array.ndim() != 1) throw py::type_error(expected + ", got " + std::to_string(array.ndim()) + " dimensions");
        for (const py::handle item : values) numbers.push_back(to_number(item, name + " element"));
        return numbers;
    }
    const char kind = array.dtype().kind();
    if (kind != 'f' && kind != 'i' && kind != 'u')
        throw py::type_error(expected + ", got elements of dtype " + py::str(array.dtype()).cast<std::string>());
    if (array.ndim() != 1) throw py::type_error(expected + ", got " + std::to_string(array.ndim()) + " dimensions");
    const auto doubles = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(array);
    return {doubles.data(), doubles.data() + doubles.size()};
}

}  // namespace fretbuzz::python
