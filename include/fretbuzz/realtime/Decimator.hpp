#pragma once
// Band-limited decimation by an integer factor M: a linear-phase low-pass FIR (windowed sinc,
// Kaiser window) designed once, evaluated only at every M-th input sample (the polyphase
// saving). It is DSP, not physics: the real-time engine steps the string at M times the host
// rate and hands the host one sample in M. Nothing allocates after construction.
#include <cstddef>
#include <vector>

namespace fretbuzz {

class Decimator {
public:
    // factor M >= 1; taps_per_phase: filter length / M (the transition band narrows as it
    // grows); cutoff: the -6 dB edge as a fraction of the output rate (< 0.5).
    Decimator(int factor, int taps_per_phase = 64, double cutoff = 0.45);

    int factor() const { return factor_; }
    std::size_t length() const { return taps_.size(); }
    // Feeds one input sample; after every M-th one, output() is the next output sample.
    void push(double x) {
        history_[position_] = x;
        history_[position_ + taps_.size()] = x;
        if (++position_ == taps_.size()) position_ = 0;
    }
    double output() const;
    // The filter is linear-phase (symmetric taps): every output lags the input by this many
    // output samples, (length - 1) / (2 M).
    double group_delay() const { return 0.5 * static_cast<double>(taps_.size() - 1) / static_cast<double>(factor_); }
    void reset();
    // The filter's gain at frequency f (as a fraction of the input rate), for tests.
    double gain_at(double f) const;

private:
    int factor_;
    std::vector<double> taps_;     // reversed impulse response: taps_[0] meets the oldest sample
    std::vector<double> history_;  // the last length() inputs, stored twice (contiguous window)
    std::size_t position_ = 0;
};

}  // namespace fretbuzz
