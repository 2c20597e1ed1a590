#include "fretbuzz/run/Resampler.hpp"

#include <soxr.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <numbers>
#include <stdexcept>
#include <string>

namespace fretbuzz {

namespace {
constexpr std::size_t kBlockFrames = 1 << 14;
soxr_t as_soxr(void* p) { return static_cast<soxr_t>(p); }

void* create(double input_rate, double output_rate, std::size_t channels) {
    soxr_error_t error = nullptr;
    const soxr_io_spec_t io = soxr_io_spec(SOXR_FLOAT64_I, SOXR_FLOAT64_I);
    // Very high quality: 28-bit precision, linear phase; its anti-aliasing filter is the band limit.
    const soxr_quality_spec_t quality = soxr_quality_spec(SOXR_VHQ, 0);
    soxr_t s = soxr_create(input_rate, output_rate, static_cast<unsigned>(channels), &error, &io, &quality, nullptr);
    if (error != nullptr) throw std::runtime_error(std::string("libsoxr: ") + error);
    return s;
}
}  // namespace

Resampler::Resampler(double input_rate_hz, double output_rate_hz, std::size_t channels)
    : input_rate_(input_rate_hz),
      output_rate_(output_rate_hz),
      channels_(channels),
      soxr_(create(input_rate_hz, output_rate_hz, channels)) {
    block_.resize(kBlockFrames * channels);
    for (long q = 1; q <= 1000; ++q) {
        const double p = input_rate_ * static_cast<double>(q) / output_rate_;
        if (std::abs(p - std::round(p)) <= 1e-9 * p) {
            input_period_ = std::lround(p);
            output_period_ = q;
            break;
        }
    }
}

Resampler::~Resampler() { soxr_delete(as_soxr(soxr_)); }

void Resampler::clear() { soxr_clear(as_soxr(soxr_)); }

void Resampler::process(std::span<const double> frames, std::vector<double>& out, bool flush) {
    const std::size_t width = channels_;
    auto run = [&](const double* in, std::size_t count, std::size_t& consumed) {
        std::size_t produced = 0;
        const soxr_error_t error =
            soxr_process(as_soxr(soxr_), in, count, &consumed, block_.data(), kBlockFrames, &produced);
        if (error != nullptr) throw std::runtime_error(std::string("libsoxr: ") + error);
        out.insert(out.end(), block_.begin(), block_.begin() + static_cast<std::ptrdiff_t>(produced * width));
        return produced;
    };
    const std::size_t count = frames.size() / width;
    std::size_t offset = 0;
    while (offset < count) {
        std::size_t consumed = 0;
        run(frames.data() + offset * width, count - offset, consumed);
        offset += consumed;
    }
    if (flush) {  // end of input: drain the filter's tail
        std::size_t consumed = 0;
        while (run(nullptr, 0, consumed) > 0) {
        }
    }
}

namespace {
// One measurement per pair of rates in a process (as FFTW's plans): the runs of a sweep, of the
// Python module or of a benchmark share it. At 4 MHz in it is a noticeable part of a short
// run: the response to an impulse 2 x 256 output frames long.
struct Measured {
    std::vector<double> impulse;
    long centre, reach;
};
std::mutex measured_mutex;
std::map<std::pair<double, double>, Measured>& measured() {
    static std::map<std::pair<double, double>, Measured> responses;
    return responses;
}
}  // namespace

void Resampler::measure() const {
    if (impulse_centre_ >= 0) return;
    const std::pair<double, double> rates{input_rate_, output_rate_};
    {
        std::lock_guard lock(measured_mutex);
        if (const auto it = measured().find(rates); it != measured().end()) {
            impulse_ = it->second.impulse;
            impulse_centre_ = it->second.centre;
            reach_ = it->second.reach;
            return;
        }
    }
    measure_response();
    std::lock_guard lock(measured_mutex);
    measured().try_emplace(rates, Measured{impulse_, impulse_centre_, reach_});
}

void Resampler::measure_response() const {
    // An impulse at an output instant, far enough from the start that nothing is cut: the
    // output around it is the filter sampled at the output rate. 1024 output frames either
    // side is several times the very-high-quality filter's reach at any ratio; 256 is enough
    // where the filter is short (downsampling: about 150 frames) and costs a quarter (at
    // 4 MHz in, the longer probe is 170 000 input samples, run at the start of every run).
    const long period = std::max(1L, input_period_);
    for (const double frames : {256.0, 1024.0}) {
        Resampler probe(input_rate_, output_rate_, 1);
        const long lead =
            period * static_cast<long>(std::ceil(frames * input_rate_ / output_rate_ / static_cast<double>(period)));
        std::vector<double> input(static_cast<std::size_t>(2 * lead) + 1, 0.0);
        input[static_cast<std::size_t>(lead)] = 1.0;
        impulse_.clear();
        probe.process(input, impulse_, true);
        impulse_centre_ = std::lround(static_cast<double>(lead) * output_rate_ / input_rate_);
        double peak = 0.0;
        for (double h : impulse_) peak = std::max(peak, std::abs(h));
        reach_ = 0;
        for (std::size_t m = 0; m < impulse_.size(); ++m)
            if (std::abs(impulse_[m]) > 1e-13 * peak)
                reach_ = std::max(reach_, std::abs(static_cast<long>(m) - impulse_centre_));
        if (static_cast<double>(reach_) < 0.75 * frames) return;  // the whole response, with room
    }
}

long Resampler::reach() const {
    measure();
    return reach_;
}

std::complex<double> Resampler::gain(std::complex<double> s) const {
    measure();
    if (std::abs(s.imag()) >= std::numbers::pi * output_rate_) return 0.0;
    // The filter's spectrum from its samples at the output rate (it is band-limited below the
    // output Nyquist frequency); each input sample weighs input/output rate output samples.
    // e^{-s m / rate} by turning one phasor (a run asks this for every audio mode: one exp per
    // tap was most of a short run's set-up); its relative round-off stays under (2 reach + 1) eps.
    const std::complex<double> turn = std::exp(-s / output_rate_);
    std::complex<double> phasor = std::exp(s * (static_cast<double>(reach_) / output_rate_));
    std::complex<double> sum = 0.0;
    for (long m = -reach_; m <= reach_; ++m, phasor *= turn) {
        const auto at = static_cast<std::size_t>(impulse_centre_ + m);
        if (at < impulse_.size()) sum += impulse_[at] * phasor;
    }
    return sum * (input_rate_ / output_rate_);
}

}  // namespace fretbuzz
