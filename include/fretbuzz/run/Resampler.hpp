#pragma once
// A streaming band-limiting resampler (libsoxr, very high quality: 28-bit precision, linear
// phase, delay compensated: output frame m stands for time m / output rate from the stream's
// first input frame). Besides resampling it describes its own filter, measured once from its
// impulse response, so that a signal known in closed form (sums of damped sinusoids) can be
// written directly at the output rate as the resampler would have produced it.
#include <complex>
#include <cstddef>
#include <span>
#include <vector>

namespace fretbuzz {

class Resampler {
public:
    Resampler(double input_rate_hz, double output_rate_hz, std::size_t channels);
    ~Resampler();
    Resampler(const Resampler&) = delete;
    Resampler& operator=(const Resampler&) = delete;

    std::size_t channels() const { return channels_; }
    double input_rate_hz() const { return input_rate_; }
    double output_rate_hz() const { return output_rate_; }

    // Feeds interleaved frames (channels() values each); appends the output frames produced to
    // `out` (interleaved). With flush, the input ends here: the filter's tail follows.
    void process(std::span<const double> frames, std::vector<double>& out, bool flush = false);
    // Forgets every input: the next frame starts a new stream.
    void clear();

    // The smallest numbers of input and output frames spanning the same time (0, 0 when the
    // rates have no common period of at most 1000 output frames): a stream started at a
    // multiple of input_period() keeps its output instants on the first stream's grid.
    long input_period() const { return input_period_; }
    long output_period() const { return output_period_; }
    // Output frames either side of an output instant beyond which the input does not count
    // (its impulse response is below 1e-13 of its peak there).
    long reach() const;
    // The output, away from a stream's ends, for the input e^{s t} (s in 1/s): gain(s) e^{s t_m}.
    // Exact to the resampler's precision below its passband's end; zero from the output
    // Nyquist frequency up (the filter's stopband).
    std::complex<double> gain(std::complex<double> s) const;

private:
    void measure() const;           // the response, measured or as this process measured it
    void measure_response() const;  // through a resampler of its own

    double input_rate_, output_rate_;
    std::size_t channels_;
    void* soxr_ = nullptr;
    std::vector<double> block_;
    long input_period_ = 0, output_period_ = 0;
    mutable std::vector<double> impulse_;  // output around an impulse at output instant impulse_centre_
    mutable long impulse_centre_ = -1;
    mutable long reach_ = 0;
};

}  // namespace fretbuzz
