#pragma once
// Audio files, one mono WAV per observation point: the audio the run makes at the rate asked
// for (band-limited and resampled from every time step, see RunObserver::audio_request),
// collected, high-passed as a pickup would (no DC), peak-normalised per file and written as
// 24-bit PCM WAV by libsndfile. The displacement is what an optical sensor sees; the velocity
// is closer to what a magnetic pickup senses.
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "fretbuzz/run/RunObserver.hpp"

namespace fretbuzz {

// Raised-cosine fades applied to each file as it is written (the signal itself, samples(),
// is left as it is). A plucked string starts displaced, so its first sample is far from
// zero: without a fade-in the file starts with a click.
struct AudioFades {
    double in_s = 0.005;
    double out_s = 0.0;
};

// The file names for the observation points, in order: "audio.wav" (or "velocity.wav")
// for the first point, then "audio_<x>m.wav" with x in metres for the others.
std::vector<std::string> audio_file_names(AudioSignal signal, std::span<const double> points_m);

// Writes one mono signal as a pickup passes it (no DC: PickupHighPass, from rest at the first
// sample), peak-normalised (to 0.99): WAV PCM of `bits` (16 or 24) bits, FLAC of `bits` bits
// when the path ends in .flac, or Ogg Vorbis when it ends in .ogg (in any case); returns what
// full scale stands for (the gain's inverse).
// std::runtime_error if the file cannot be written. Every audio file fretbuzz writes goes
// through here (run outputs, `fretbuzz play`, the notes of sweeps and set-up studies).
double write_normalised_audio(const std::filesystem::path& path, std::span<const double> signal, double rate_hz,
                              int bits = 24);
// The same with raised-cosine fades over the first `fade_in` and the last `fade_out` samples
// (the peak is that of the high-passed, faded signal), read without copying it.
double write_faded_audio(const std::filesystem::path& path, std::span<const double> signal, double rate_hz, int bits,
                         std::size_t fade_in, std::size_t fade_out);

// A compact copy of a sound, for embedding in a page: Ogg Vorbis at the encoder's variable-bit-
// rate quality `quality` (0 to 1; 0.1 is some 40 kbit/s for a mono note at 48 kHz), the pickup's
// high-pass and the normalisation as above; ".ogg" is added to a path without it.
void write_compact_audio(const std::filesystem::path& path, std::span<const double> signal, double rate_hz,
                         double quality = 0.1);

class AudioWriter : public RunObserver {
public:
    // One path per observation point, in the order of the case's points. angle_deg: the
    // direction of the displacement taken (see AudioRequest; two polarisations).
    AudioWriter(std::vector<std::filesystem::path> paths, double audio_rate_hz,
                AudioSignal signal = AudioSignal::displacement, AudioFades fades = {}, double angle_deg = 0.0);

    void begin(const RunLayout& layout) override;
    AudioRequest audio_request() const override { return {.rate_hz = rate_, .signal = signal_, .angle_deg = angle_}; }
    void audio(long first_sample, std::span<const double> samples) override;
    void finish(const RunSummary&) override;

    // The resampled signal of one point before normalisation (available after finish()).
    const std::vector<double>& samples(std::size_t point = 0) const { return channels_.at(point); }
    double rate_hz() const { return rate_; }
    // What full scale (a sample of 1.0) stands for in each file, in m (displacement) or m/s
    // (velocity): files are peak-normalised to 0.99 of full scale (after finish()).
    double full_scale(std::size_t point) const { return full_scale_.at(point); }
    const std::vector<std::filesystem::path>& paths() const { return paths_; }
    AudioSignal signal() const { return signal_; }
    const AudioFades& fades() const { return fades_; }

private:
    void write_channel(std::size_t point);

    std::vector<std::filesystem::path> paths_;
    double rate_;
    AudioSignal signal_;
    AudioFades fades_;
    double angle_;
    std::vector<double> full_scale_;
    std::vector<std::vector<double>> channels_;
};

}  // namespace fretbuzz
