// The paper's observations on the bass 'pop' (Issanchou et al. 2017, section 5), checked on
// a short run: the formant near 4.5 kHz during the contacts, and the step-wise energy
// decay while the string hits the frets. (docs/validation.md has the full studies.)
#include <fftw3.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/run/Simulation.hpp"

namespace fretbuzz {
namespace {

struct Trace : RunObserver {
    void observation(double t, std::span<const double> u) override {
        time.push_back(t);
        signal.push_back(u.front());
    }
    void energy(double, double h, double, double) override { energy_j.push_back(h); }
    std::vector<double> time, signal, energy_j;
};

Trace run_pop(bool with_frets) {
    Case c = load_case("bass-pop");
    c.run.duration_s = 0.085;
    c.run.output_rate_hz = 48000.0;
    if (!with_frets) c.obstacle_height_m.assign(c.mode_count(), -std::numeric_limits<double>::infinity());
    Trace trace;
    RunObserver* observers[] = {&trace};
    simulate(c, observers);
    return trace;
}

// Short-time power spectra (20 ms Hann frames, 5 ms hop) averaged over frames centred in
// [from, to] s, then smoothed over 500 Hz; returns (bin width, spectrum).
std::pair<double, std::vector<double>> contact_phase_spectrum(const Trace& trace, double from, double to) {
    const double rate = 1.0 / (trace.time[1] - trace.time[0]);
    const auto width = static_cast<std::size_t>(0.02 * rate), hop = static_cast<std::size_t>(0.005 * rate);
    std::vector<double> frame(width), power(width / 2 + 1, 0.0);
    std::vector<fftw_complex> spectrum(width / 2 + 1);
    fftw_plan plan = fftw_plan_dft_r2c_1d(static_cast<int>(width), frame.data(), spectrum.data(), FFTW_ESTIMATE);
    std::vector<double> hann(width);
    for (std::size_t k = 0; k < width; ++k)
        hann[k] = 0.5 * (1.0 - std::cos(2.0 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(width - 1)));
    int frames = 0;
    for (std::size_t s = 0; s + width <= trace.signal.size(); s += hop) {
        const double centre = trace.time[s + width / 2];
        if (centre < from || centre > to) continue;
        for (std::size_t k = 0; k < width; ++k) frame[k] = trace.signal[s + k] * hann[k];
        fftw_execute(plan);
        for (std::size_t k = 0; k < power.size(); ++k)
            power[k] += spectrum[k][0] * spectrum[k][0] + spectrum[k][1] * spectrum[k][1];
        ++frames;
    }
    fftw_destroy_plan(plan);
    const double bin = rate / static_cast<double>(width);
    const auto half = static_cast<std::ptrdiff_t>(250.0 / bin);
    std::vector<double> smooth(power.size(), 0.0);
    for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(power.size()); ++k) {
        int count = 0;
        for (std::ptrdiff_t m = k - half; m <= k + half; ++m)
            if (m >= 0 && m < static_cast<std::ptrdiff_t>(power.size())) {
                smooth[static_cast<std::size_t>(k)] += power[static_cast<std::size_t>(m)] / frames;
                ++count;
            }
        smooth[static_cast<std::size_t>(k)] /= count;
    }
    return {bin, smooth};
}

double decibels_at(const std::pair<double, std::vector<double>>& s, double f) {
    return 10.0 * std::log10(s.second[static_cast<std::size_t>(std::lround(f / s.first))]);
}

TEST(PaperObservations, FormantNearFourPointFiveKilohertzDuringTheContacts) {
    const Trace fretted = run_pop(true), free = run_pop(false);
    const auto contact = contact_phase_spectrum(fretted, 0.005, 0.080);
    const auto no_obstacle = contact_phase_spectrum(free, 0.005, 0.080);
    // The largest level between 3.8 and 5.2 kHz sits near 4.5 kHz ...
    double peak_f = 0.0, peak_db = -1e300;
    for (double f = 3800.0; f <= 5200.0; f += contact.first)
        if (decibels_at(contact, f) > peak_db) {
            peak_db = decibels_at(contact, f);
            peak_f = f;
        }
    EXPECT_NEAR(peak_f, 4500.0, 250.0);
    // ... standing out from its neighbours (a formant, not just a slope) ...
    EXPECT_GT(peak_db - std::max(decibels_at(contact, peak_f - 500.0), decibels_at(contact, peak_f + 500.0)), 3.0);
    // ... and it comes from the contacts: far above the same string without frets.
    EXPECT_GT(peak_db - decibels_at(no_obstacle, peak_f), 12.0);
}

TEST(PaperObservations, EnergyFallsStepWiseWhileTheStringHitsTheFrets) {
    const Trace fretted = run_pop(true), free = run_pop(false);
    // Until the last contact (80 ms) the frets take far more energy than damping alone.
    const double kept_fretted = fretted.energy_j.back() / fretted.energy_j.front();
    const double kept_free = free.energy_j.back() / free.energy_j.front();
    EXPECT_LT(kept_fretted, 0.5);
    EXPECT_GT(kept_free, 0.9);
    // Step-wise: the steepest 1 ms of the decay is far steeper than the average rate.
    const double rate = 1.0 / (fretted.time[1] - fretted.time[0]);
    const auto ms = static_cast<std::size_t>(0.001 * rate);
    double steepest = 0.0;
    for (std::size_t k = ms; k < fretted.energy_j.size(); ++k)
        steepest = std::max(steepest, (fretted.energy_j[k - ms] - fretted.energy_j[k]) / fretted.energy_j.front());
    const double average_per_ms = (1.0 - kept_fretted) / 85.0;
    EXPECT_GT(steepest, 5.0 * average_per_ms);
}

}  // namespace
}  // namespace fretbuzz
