#include "fretbuzz/scheme/SamplingCheck.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>
#include <sstream>
#include <vector>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/numerics/ModalBasis.hpp"

namespace fretbuzz {

namespace {

constexpr std::size_t kListedRanges = 4;

// "modes 395-788 (88.3-176.2 kHz)": consecutive modes as ranges, a few ranges at most.
std::string describe(const std::vector<AliasedMode>& modes) {
    std::ostringstream out;
    out.precision(4);
    out << (modes.size() == 1 ? "mode " : "modes ");
    std::size_t ranges = 0, k = 0;
    while (k < modes.size()) {
        std::size_t end = k;
        while (end + 1 < modes.size() && modes[end + 1].mode == modes[end].mode + 1) ++end;
        if (ranges == kListedRanges) {
            out << ", ... (" << modes.size() << " modes in all)";
            break;
        }
        if (ranges > 0) out << ", ";
        out << modes[k].mode;
        if (end > k) out << "-" << modes[end].mode;
        out << " (" << modes[k].frequency_hz / 1e3;
        if (end > k) out << "-" << modes[end].frequency_hz / 1e3;
        out << " kHz)";
        ++ranges;
        k = end + 1;
    }
    return out.str();
}

}  // namespace

SamplingReport check_sampling(const ModeTable& modes, double fs) {
    SamplingReport report;
    if (modes.size() == 0 || !(fs > 0.0)) return report;
    const double lowest = *std::min_element(modes.frequency_hz.begin(), modes.frequency_hz.end());
    report.floor_hz = kAliasFloor * lowest;
    for (std::size_t j = 0; j < modes.size(); ++j) {
        const double nu = modes.frequency_hz[j];
        if (!(nu > 0.5 * fs)) continue;
        const AliasedMode m{j + 1, nu, std::abs(nu - std::round(nu / fs) * fs)};
        report.above_nyquist.push_back(m);
        if (m.alias_hz < report.floor_hz) report.hazardous.push_back(m);
    }
    if (!report.above_nyquist.empty()) {
        std::ostringstream out;
        out.precision(6);
        out << "run.fs = " << fs << " Hz: " << describe(report.above_nyquist) << (report.above_nyquist.size() == 1 ? " lies" : " lie") << " above fs/2 = " << 0.5 * fs
            << " Hz; under contact each acts as a mode at its alias |nu - k fs|, so contact results carry an "
               "error even though the energy balances (keep fs > 2 nu_max = "
            << 2.0 * *std::max_element(modes.frequency_hz.begin(), modes.frequency_hz.end()) << " Hz, or fewer modes)";
        report.warnings.push_back(out.str());
    }
    for (const AliasedMode& m : report.hazardous) {
        std::ostringstream out;
        out.precision(6);
        out << "run.fs = " << fs << " Hz: mode " << m.mode << " (" << m.frequency_hz << " Hz) lies " << m.alias_hz
            << " Hz from " << std::round(m.frequency_hz / fs) << " fs and acts under contact as a " << m.alias_hz
            << " Hz mode, below " << kAliasFloor << " x the lowest mode (" << report.floor_hz
            << " Hz): contact results are wrong";
        report.warnings.push_back(out.str());
    }
    return report;
}

SamplingReport require_sampling(const ModeTable& modes, double fs, bool allow_aliasing) {
    SamplingReport report = check_sampling(modes, fs);
    if (report.hazardous.empty() || allow_aliasing) return report;
    const AliasedMode& first = report.hazardous.front();
    double highest = 0.0;
    for (double nu : modes.frequency_hz) highest = std::max(highest, nu);
    std::ostringstream out;
    out.precision(6);
    out << "run.fs = " << fs << " Hz is too low for the modes: " << describe(report.hazardous)
        << (report.hazardous.size() == 1 ? " lies" : " lie") << " within " << report.floor_hz << " Hz (" << kAliasFloor
        << " x the lowest mode frequency) of a multiple of fs, where under contact a mode acts as a very low "
           "mode (mode "
        << first.mode << " as a " << first.alias_hz << " Hz mode) that corrupts the result. Set run.fs above "
        << 2.0 * highest << " Hz (2 x the highest mode), use at most " << first.mode - 1
        << " modes (string.modes), or set run.allow_aliasing = true (--allow-aliasing) to run anyway";
    throw InputError(out.str());
}

bool contact_possible(const Case& c) {
    if (!c.fingers.empty() || !c.forces.empty() || !c.plucks.empty()) return true;
    if (!c.has_obstacle()) return false;
    // Free motion: each mode's energy (v^2 + omega^2 q^2) / 2 never grows (sigma >= 0), so
    // |q_j(t)| <= sqrt(q_j(0)^2 + (v_j(0) / omega_j)^2) = a_j, and |u(x_i, t)| <= sum_j
    // |S_ij| a_j. The modal update is exact for free motion: the steps obey the same bound.
    const std::size_t n = c.mode_count();
    std::vector<double> reach(n);
    for (std::size_t j = 0; j < n; ++j) {
        const double omega = 2.0 * std::numbers::pi * c.modes.frequency_hz[j];
        const double q = c.initial_displacement[j], v = c.initial_velocity[j] / omega;
        reach[j] = std::sqrt(q * q + v * v);
    }
    const ModalBasis basis(c.string.length_m, n);
    std::vector<double> row(n);
    const double s = c.contact_orientation();
    const auto reaches = [&](std::span<const double> phi, double g) {
        double bound = 0.0;
        for (std::size_t j = 0; j < n; ++j) bound += std::abs(phi[j]) * reach[j];
        return bound * (1.0 + 1e-9) >= -s * g;  // u can reach g (a margin for round-off)
    };
    // Points first: a fretboard's crowns stand above its board (a few rows, not hundreds).
    for (const PointObstacle& p : c.point_obstacles) {
        basis.mode_shapes_at(p.x_m, row);
        if (reaches(row, p.height_m)) return true;
    }
    for (std::size_t i = 0; i < n; ++i) {
        const double g = c.obstacle_height_m[i];
        if (std::isfinite(g) && reaches(basis.row(i, row), g)) return true;
    }
    return false;
}

std::size_t modes_below_nyquist(const ModeTable& modes, double fs) {
    std::size_t n = 0;
    while (n < modes.size() && !(modes.frequency_hz[n] > 0.5 * fs)) ++n;
    return n;
}

}  // namespace fretbuzz
