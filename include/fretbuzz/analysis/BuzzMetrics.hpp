#pragma once
// How much a run buzzed, measured while it goes (docs/sweeps.md gives each formula):
// where the string touched the obstacle (grid points, and the obstacle's "features": its
// local peaks, i.e. the frets of a fretboard, numbered from the nut), when, in how many
// episodes, for how long, with what force, the energy dissipated while touching, and the
// high-frequency energy of the first observation signal, which, compared with the same
// run without the obstacle, gives the audible buzz level in dB (see SweepRunner).
#include <cstddef>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "fretbuzz/run/RunObserver.hpp"

namespace fretbuzz {

struct Case;

struct BuzzReport {
    static constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    std::size_t touched_points = 0;       // grid points that ever carried a force
    double touched_x_min_m = nan, touched_x_max_m = nan;
    std::vector<std::size_t> touched_features;  // 1-based, from the nut, increasing
    std::size_t main_feature = 0;         // the feature with the largest impulse (0: none)
    double first_contact_s = nan, last_contact_s = nan;
    long contact_steps = 0;
    long episodes = 0;                    // contact steps grouped: a gap longer than episode_gap_s ends one
    double contact_time_s = 0.0;          // contact_steps * dt
    double energy_lost_in_contact_j = 0.0;  // damping losses over output intervals with contact
    double peak_force_n = 0.0;            // max over steps of sum_i f_i dx
    double impulse_n_s = 0.0;             // sum over steps of sum_i f_i dx dt
    double high_frequency_energy = nan;   // sum of |U(f)|^2 above the band edge (m^2), Hann window
};

// The obstacle's features: maximal plateaus of g strictly higher than both neighbours
// (the frets of a fretboard, a bridge's crest, a point obstacle). Returns, per grid
// point, the 1-based feature nearest to it (0 when the obstacle has none).
std::vector<std::size_t> obstacle_features(std::span<const double> obstacle_height_m);

// A finger stopping the string holds it on a fret: the contacts from the nut up to that fret
// (the finger's pad, the fret it stops on) are the fretting, not buzz. Returns the first grid
// point past them: the first point of the next obstacle feature beyond the stopping fret,
// the stopping fret being the first fret at or past the bridge-side edge of the
// bridge-most finger. 0 for a case without fingers (every contact counts).
std::size_t first_buzz_point(const Case& c);
// The case with nothing to touch from grid point `first` on, its exact points (frets off the
// grid) from half a grid step before it; first = 0: nothing at all (a note's clean reference).
Case without_obstacle_from(const Case& c, std::size_t first);

// High-frequency energy of a signal sampled at rate_hz: sum over the one-sided spectrum
// of the Hann-windowed signal of |U_k|^2 for f_k >= band_hz (NaN if band_hz >= rate/2).
double high_frequency_energy(std::span<const double> signal, double rate_hz, double band_hz);
// |U_k|^2, k = 0..n/2, of the Hann-windowed signal (n = signal.size() >= 2).
std::vector<double> hann_power_spectrum(std::span<const double> signal);

class BuzzMetrics : public RunObserver {
public:
    // band_hz: lower edge of the buzz band. episode_gap_s: contacts closer than this in
    // time (the string bouncing on a fret) belong to one episode.
    explicit BuzzMetrics(double band_hz = 2000.0, double episode_gap_s = 2e-4)
        : band_hz_(band_hz), episode_gap_s_(episode_gap_s) {}
    void begin(const RunLayout& layout) override;
    void observation(double t, std::span<const double> u) override;
    void energy(double t, double h, double contact, double dissipated) override;
    void contacts(double t, std::span<const std::pair<std::size_t, double>> forces) override;
    void finish(const RunSummary& summary) override;
    const BuzzReport& report() const { return report_; }
    // The first observation signal at the output rate, as measured.
    const std::vector<double>& signal() const { return signal_; }

private:
    double band_hz_;
    double episode_gap_s_;
    double dt_ = 0.0, dx_ = 0.0, output_rate_ = 0.0;
    std::vector<std::size_t> feature_of_point_;
    std::size_t first_counted_ = 0;  // contacts before this grid point are fretting (first_buzz_point)
    std::vector<char> hand_;         // pad points of fingers and force gestures: never counted
    std::vector<double> feature_impulse_;
    std::vector<char> touched_;
    std::vector<double> signal_;
    double last_contact_t_ = -1.0;
    bool contact_since_energy_ = false;
    double last_dissipated_ = 0.0;
    bool have_dissipated_ = false;
    BuzzReport report_;
};

// 10 log10(a / b) in dB (NaN unless both are > 0): with a = E_hf(with obstacle) and
// b = E_hf(without), how the buzz band's level changed; with a = E_hf(u - u_free), the
// contact-generated buzz relative to the note's own high-frequency content.
double buzz_level_db(double high_frequency_energy, double obstacle_free_high_frequency_energy);

}  // namespace fretbuzz
