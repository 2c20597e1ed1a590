#pragma once
// Vectors to NumPy arrays (copies) and back, for the bindings.
#include <pybind11/numpy.h>

#include <string>
#include <vector>

namespace fretbuzz::python {

inline pybind11::array_t<double> to_numpy(const std::vector<double>& v) {
    return pybind11::array_t<double>(static_cast<pybind11::ssize_t>(v.size()), v.data());
}

// Any 1-D sequence of numbers; `name` is the field named in the error.
inline std::vector<double> to_vector(pybind11::handle values, const std::string& name) {
    const auto array = pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>::ensure(values);
    if (!array || array.ndim() != 1) throw pybind11::value_error(name + ": expected a 1-D sequence of numbers");
    return {array.data(), array.data() + array.size()};
}

}  // namespace fretbuzz::python
