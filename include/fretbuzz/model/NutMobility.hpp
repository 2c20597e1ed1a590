#pragma once
// Mobility Y_s(omega) of the nut (velocity over force, m/s/N), the weak coupling of the
// string to the neck (Issanchou et al. 2017, sections 2.4 and 2.5). It is measured, so it
// is given as a table of frequency, Re Y_s, Im Y_s, interpolated linearly in frequency.
// Outside the measured band the nut is taken as rigid (Y_s = 0): the paper only
// accounts for the mobility where it was measured (up to about 10 kHz).
#include <complex>
#include <string>
#include <vector>

namespace fretbuzz {

class NutMobility {
public:
    // A rigid nut: Y_s = 0 at every frequency.
    NutMobility() = default;
    // frequency_hz must increase strictly; all values finite. Throws InputError naming source.
    NutMobility(std::vector<double> frequency_hz, std::vector<double> real_part, std::vector<double> imaginary_part,
                const std::string& source);

    bool is_rigid() const { return frequency_hz_.empty(); }
    // Y_s at the frequency nu (Hz), i.e. at omega = 2 pi nu.
    std::complex<double> at_frequency(double frequency_hz) const;

private:
    std::vector<double> frequency_hz_;
    std::vector<double> real_;
    std::vector<double> imaginary_;
};

}  // namespace fretbuzz
