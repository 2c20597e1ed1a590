#pragma once
// audio.wav: the first observation signal, taken at every time step, band-limited and
// resampled to the audio rate by libsoxr (streaming, so a long run never holds its
// full-rate signal), peak-normalised and written as 24-bit PCM WAV by libsndfile.
#include <filesystem>
#include <memory>
#include <vector>

#include "fretbuzz/run/RunObserver.hpp"

namespace fretbuzz {

class AudioWriter : public RunObserver {
public:
    AudioWriter(const std::filesystem::path& path, double audio_rate_hz);
    ~AudioWriter() override;
    void begin(const RunLayout& layout) override;
    bool wants_every_step() const override { return true; }
    void every_step(std::span<const double> u, std::span<const double> velocity) override;
    void finish(const RunSummary&) override;

    // The resampled signal before normalisation (available after finish()).
    const std::vector<double>& samples() const { return output_; }

private:
    void drain(bool flush);

    std::filesystem::path path_;
    double rate_;
    void* resampler_ = nullptr;
    std::vector<double> input_;
    std::vector<double> block_;
    std::vector<double> output_;
};

}  // namespace fretbuzz
