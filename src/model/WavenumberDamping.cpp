#include "fretbuzz/model/WavenumberDamping.hpp"

#include <numbers>

namespace fretbuzz {

double WavenumberDamping::sigma_per_s(std::size_t j, double) const {
    const double k = static_cast<double>(j) * std::numbers::pi / length_m_;
    return eta0_ + eta2_ * k * k;
}

}  // namespace fretbuzz
