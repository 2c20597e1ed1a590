#pragma once
// What the mode table needs of a damping model: sigma_j (1/s) of mode j at its frequency.
#include <cstddef>
#include <numbers>

namespace fretbuzz {

// The quality factor of a partial of frequency nu (Hz) decaying at sigma (1/s, its amplitude
// as exp(-sigma t)): Q = pi nu / sigma = omega / (2 sigma); 1/Q of its energy is lost per
// radian of its phase.
inline double quality_factor(double frequency_hz, double sigma_per_s) { return std::numbers::pi * frequency_hz / sigma_per_s; }

class ModalDamping {
public:
    virtual ~ModalDamping() = default;
    virtual double sigma_per_s(std::size_t j, double frequency_hz) const = 0;
};

}  // namespace fretbuzz
