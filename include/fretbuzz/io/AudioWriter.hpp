#pragma once
// Audio files, one mono WAV per observation point: the signal taken at every time step,
// band-limited and resampled to the audio rate by libsoxr (streaming, so a long run never
// holds its full-rate signal), peak-normalised per file and written as 24-bit PCM WAV by
// libsndfile. The displacement is what an optical sensor sees; the velocity is closer to
// what a magnetic pickup senses.
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "fretbuzz/run/RunObserver.hpp"

namespace fretbuzz {

enum class AudioSignal { displacement, velocity };

// The file names for the observation points, in order: "audio.wav" (or "velocity.wav")
// for the first point, then "audio_<x>m.wav" with x in metres for the others.
std::vector<std::string> audio_file_names(AudioSignal signal, std::span<const double> points_m);

// Writes one mono signal peak-normalised (to 0.99): WAV PCM of `bits` (16 or 24) bits, or
// Ogg Vorbis when the path ends in .ogg. std::runtime_error if the file cannot be written.
void write_normalised_audio(const std::filesystem::path& path, std::span<const double> signal, double rate_hz,
                            int bits = 24);

class AudioWriter : public RunObserver {
public:
    // One path per observation point, in the order of the case's points.
    AudioWriter(std::vector<std::filesystem::path> paths, double audio_rate_hz,
                AudioSignal signal = AudioSignal::displacement);
    ~AudioWriter() override;
    AudioWriter(const AudioWriter&) = delete;
    AudioWriter& operator=(const AudioWriter&) = delete;

    void begin(const RunLayout& layout) override;
    bool wants_every_step() const override { return true; }
    // While no contact is possible the run may feed only the modes below 0.6 x the audio
    // rate (the resampler removes the others anyway). Switching the out-of-band modes off
    // and on at the edges of those stretches leaves a trace of about -110 dB relative to
    // the signal (tests/test_long_run.cpp); `fretbuzz run --no-free-flight` avoids it.
    double every_step_band_hz() const override { return 0.6 * rate_; }
    bool wants_velocity() const override { return signal_ == AudioSignal::velocity; }
    void every_step(std::span<const double> u, std::span<const double> velocity) override;
    void finish(const RunSummary&) override;

    // The resampled signal of one point before normalisation (available after finish()).
    const std::vector<double>& samples(std::size_t point = 0) const { return channels_.at(point); }
    double rate_hz() const { return rate_; }

private:
    void drain(bool flush);
    void write_channel(std::size_t point) const;

    std::vector<std::filesystem::path> paths_;
    double rate_;
    AudioSignal signal_;
    void* resampler_ = nullptr;
    std::vector<double> input_;   // interleaved, one frame per time step
    std::vector<double> block_;   // interleaved resampler output
    std::vector<std::vector<double>> channels_;
};

}  // namespace fretbuzz
