#pragma once
// Checks, before a run, that the sampling rate fs suits the modes under contact.
//
// The per-mode update is exact for free motion at any dt, but contact forces enter it once
// per step, and to a force sampled at fs a mode of frequency nu answers like a mode at its
// alias |nu - k fs| (k = round(nu / fs)): its response to an impulse is
// sin(omega m dt) / sin(omega dt), the same sequence as for the alias. A mode above fs/2 is
// therefore folded back to a lower frequency, and one near a multiple of fs acts as a very
// low, very compliant mode that soaks up the contact (mode 789 of an ideal string at
// 176.4 kHz, 26 Hz from fs, acts as a 26 Hz mode) while the energy balance still holds.
//
// Rule (measured by scripts/aliasing_flat_barrier.py, see docs/validation.md):
//  - every mode above fs/2 is reported as a warning;
//  - a mode whose alias lies below kAliasFloor times the lowest mode frequency is an
//    error (InputError) unless aliasing is allowed (run.allow_aliasing, --allow-aliasing).
// Keeping every mode below fs/2 (fs > 2 nu_max) avoids both.
#include <cstddef>
#include <string>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/model/ModeTable.hpp"

namespace fretbuzz {

struct AliasedMode {
    std::size_t mode = 0;  // j >= 1
    double frequency_hz = 0.0;
    double alias_hz = 0.0;  // |nu_j - k fs|, k = round(nu_j / fs)
};

struct SamplingReport {
    std::vector<AliasedMode> above_nyquist;  // nu_j > fs / 2
    std::vector<AliasedMode> hazardous;      // alias below kAliasFloor * lowest frequency
    double floor_hz = 0.0;                   // that limit
    std::vector<std::string> warnings;       // one line each, for the user and summary.json
};

// An alias below this fraction of the lowest mode frequency is refused.
inline constexpr double kAliasFloor = 0.5;

// Classifies the modes of `modes` at sampling rate fs (Hz). Throws nothing.
SamplingReport check_sampling(const ModeTable& modes, double fs);
// check_sampling, then InputError naming the hazardous modes unless allow_aliasing (their
// warning is kept in the report instead).
SamplingReport require_sampling(const ModeTable& modes, double fs, bool allow_aliasing);
// Whether anything can touch the string in this case: an obstacle within reach of its free
// motion, or a finger or gesture acting on it. Without contact the modal update is exact at
// any fs and nothing aliases: the checks above apply only where this is true.
bool contact_possible(const Case& c);
// How many leading modes lie at or below fs/2: the mode count that keeps every mode in band.
std::size_t modes_below_nyquist(const ModeTable& modes, double fs);

}  // namespace fretbuzz
