#include "fretbuzz/io/AudioWriter.hpp"

#include <sndfile.h>
#include <soxr.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace fretbuzz {

namespace {
constexpr std::size_t kBlock = 1 << 14;
soxr_t as_soxr(void* p) { return static_cast<soxr_t>(p); }
}  // namespace

AudioWriter::AudioWriter(const std::filesystem::path& path, double audio_rate_hz) : path_(path), rate_(audio_rate_hz) {}

AudioWriter::~AudioWriter() {
    if (resampler_ != nullptr) soxr_delete(as_soxr(resampler_));
}

void AudioWriter::begin(const RunLayout& layout) {
    const double input_rate = 1.0 / layout.dt;
    soxr_error_t error = nullptr;
    const soxr_io_spec_t io = soxr_io_spec(SOXR_FLOAT64_I, SOXR_FLOAT64_I);
    // Very high quality: 28-bit precision, linear phase; its anti-aliasing filter is the band limit.
    const soxr_quality_spec_t quality = soxr_quality_spec(SOXR_VHQ, 0);
    resampler_ = soxr_create(input_rate, rate_, 1, &error, &io, &quality, nullptr);
    if (error != nullptr) throw std::runtime_error(std::string("libsoxr: ") + error);
    input_.reserve(kBlock);
    block_.resize(kBlock);
    output_.reserve(static_cast<std::size_t>(static_cast<double>(layout.steps) * layout.dt * rate_) + 16);
}

void AudioWriter::every_step(std::span<const double> u, std::span<const double>) {
    input_.push_back(u.front());
    if (input_.size() == kBlock) drain(false);
}

void AudioWriter::drain(bool flush) {
    auto process = [this](const double* in, std::size_t length, std::size_t& consumed) {
        std::size_t produced = 0;
        const soxr_error_t error =
            soxr_process(as_soxr(resampler_), in, length, &consumed, block_.data(), block_.size(), &produced);
        if (error != nullptr) throw std::runtime_error(std::string("libsoxr: ") + error);
        output_.insert(output_.end(), block_.begin(), block_.begin() + static_cast<std::ptrdiff_t>(produced));
        return produced;
    };
    std::size_t offset = 0;
    while (offset < input_.size()) {
        std::size_t consumed = 0;
        process(input_.data() + offset, input_.size() - offset, consumed);
        offset += consumed;
    }
    input_.clear();
    if (flush) {  // end of input: drain the filter's tail
        std::size_t consumed = 0;
        while (process(nullptr, 0, consumed) > 0) {
        }
    }
}

void AudioWriter::finish(const RunSummary& summary) {
    drain(true);
    const std::size_t expected = static_cast<std::size_t>(std::llround(summary.duration_s * rate_)) + 1;
    if (output_.size() > expected) output_.resize(expected);
    double peak = 0.0;
    for (double v : output_) peak = std::max(peak, std::abs(v));
    const double gain = peak > 0.0 ? 0.99 / peak : 1.0;
    std::vector<double> normalised(output_.size());
    std::transform(output_.begin(), output_.end(), normalised.begin(), [gain](double v) { return gain * v; });

    SF_INFO info{};
    info.samplerate = static_cast<int>(std::lround(rate_));
    info.channels = 1;
    info.format = SF_FORMAT_WAV | SF_FORMAT_PCM_24;
    SNDFILE* file = sf_open(path_.c_str(), SFM_WRITE, &info);
    if (file == nullptr) throw std::runtime_error("cannot write " + path_.string() + ": " + sf_strerror(nullptr));
    const sf_count_t written = sf_write_double(file, normalised.data(), static_cast<sf_count_t>(normalised.size()));
    sf_close(file);
    if (written != static_cast<sf_count_t>(normalised.size())) throw std::runtime_error("writing " + path_.string() + " failed");
}

}  // namespace fretbuzz
