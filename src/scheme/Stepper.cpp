#include "fretbuzz/scheme/Stepper.hpp"

namespace fretbuzz {

double Stepper::velocity(std::span<const double> mode_shapes) const {
    const ModalState& modes = string().modes();
    return kernels::dot(mode_shapes.data(), modes.d().data(), modes.size()) / string().plan().dt();
}

}  // namespace fretbuzz
