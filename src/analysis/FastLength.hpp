#pragma once
// Transform lengths FFTW runs fast: the smallest 2^a 3^b 5^c at least n.
#include <algorithm>
#include <cstddef>

namespace fretbuzz {

inline std::size_t smooth_length(std::size_t n) {
    for (std::size_t m = std::max<std::size_t>(n, 1);; ++m) {
        std::size_t r = m;
        for (std::size_t f : {2u, 3u, 5u})
            while (r % f == 0) r /= f;
        if (r == 1) return m;
    }
}

}  // namespace fretbuzz
