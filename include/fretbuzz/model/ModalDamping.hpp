#pragma once
// What the mode table needs of a damping model: sigma_j (1/s) of mode j at its frequency.
#include <cstddef>

namespace fretbuzz {

class ModalDamping {
public:
    virtual ~ModalDamping() = default;
    virtual double sigma_per_s(std::size_t j, double frequency_hz) const = 0;
};

}  // namespace fretbuzz
