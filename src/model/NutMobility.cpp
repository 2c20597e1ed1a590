#include "fretbuzz/model/NutMobility.hpp"

#include <algorithm>
#include <cmath>

#include "fretbuzz/Error.hpp"

namespace fretbuzz {

NutMobility::NutMobility(std::vector<double> frequency_hz, std::vector<double> real_part,
                         std::vector<double> imaginary_part, const std::string& source)
    : frequency_hz_(std::move(frequency_hz)), real_(std::move(real_part)), imaginary_(std::move(imaginary_part)) {
    if (frequency_hz_.empty() || real_.size() != frequency_hz_.size() || imaginary_.size() != frequency_hz_.size())
        throw InputError(source + ": the nut mobility needs rows of frequency_hz, Re Y_s, Im Y_s");
    for (std::size_t k = 0; k < frequency_hz_.size(); ++k) {
        const std::string row = source + " data row " + std::to_string(k + 1);
        require_non_negative(row + " frequency_hz", frequency_hz_[k]);
        require_finite(row + " Re Y_s", real_[k]);
        require_finite(row + " Im Y_s", imaginary_[k]);
        if (k > 0 && !(frequency_hz_[k] > frequency_hz_[k - 1]))
            throw InputError(row + ": frequency_hz must increase strictly from row to row");
    }
}

std::complex<double> NutMobility::at_frequency(double frequency_hz) const {
    if (is_rigid() || frequency_hz < frequency_hz_.front() || frequency_hz > frequency_hz_.back()) return {0.0, 0.0};
    const auto upper = std::upper_bound(frequency_hz_.begin(), frequency_hz_.end(), frequency_hz);
    if (upper == frequency_hz_.end()) return {real_.back(), imaginary_.back()};
    const auto k = static_cast<std::size_t>(upper - frequency_hz_.begin());
    const double w = (frequency_hz - frequency_hz_[k - 1]) / (frequency_hz_[k] - frequency_hz_[k - 1]);
    return {(1.0 - w) * real_[k - 1] + w * real_[k], (1.0 - w) * imaginary_[k - 1] + w * imaginary_[k]};
}

}  // namespace fretbuzz
