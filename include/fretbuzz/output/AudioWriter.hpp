#pragma once
// Audio files, one mono WAV per observation point: the signal taken at every time step,
// band-limited and resampled to the audio rate by libsoxr (streaming, so a long run never
// holds its full-rate signal; over long contact-free stretches the run writes the resampled
// signal itself in closed form, see RunObserver::resampler), peak-normalised per file and
// written as 24-bit PCM WAV by libsndfile. The displacement is what an optical sensor sees; the velocity is closer to
// what a magnetic pickup senses.
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "fretbuzz/run/Resampler.hpp"
#include "fretbuzz/run/RunObserver.hpp"

namespace fretbuzz {

enum class AudioSignal { displacement, velocity };

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

// Writes one mono signal peak-normalised (to 0.99): WAV PCM of `bits` (16 or 24) bits, or
// Ogg Vorbis when the path ends in .ogg; returns what full scale stands for (the gain's
// inverse). std::runtime_error if the file cannot be written.
double write_normalised_audio(const std::filesystem::path& path, std::span<const double> signal, double rate_hz,
                              int bits = 24);
// The same with raised-cosine fades over the first `fade_in` and the last `fade_out` samples
// (the peak is that of the faded signal), read without copying it.
double write_faded_audio(const std::filesystem::path& path, std::span<const double> signal, double rate_hz, int bits,
                         std::size_t fade_in, std::size_t fade_out);

class AudioWriter : public RunObserver {
public:
    // One path per observation point, in the order of the case's points.
    AudioWriter(std::vector<std::filesystem::path> paths, double audio_rate_hz,
                AudioSignal signal = AudioSignal::displacement, AudioFades fades = {});
    ~AudioWriter() override;
    AudioWriter(const AudioWriter&) = delete;
    AudioWriter& operator=(const AudioWriter&) = delete;

    void begin(const RunLayout& layout) override;
    bool wants_every_step() const override { return true; }
    bool per_step_only() const override { return true; }
    // While no contact is possible the run may feed only the modes below 0.6 x the audio
    // rate (the resampler removes the others anyway). Switching the out-of-band modes off
    // and on at the edges of those stretches leaves a trace of about -110 dB relative to
    // the signal (tests/test_long_run.cpp); `fretbuzz run --no-free-flight` avoids it.
    double every_step_band_hz() const override { return 0.6 * rate_; }
    bool wants_velocity() const override { return signal_ == AudioSignal::velocity; }
    void every_step(std::span<const double> u, std::span<const double> velocity) override;
    // Where no contact can act the run writes the band-limited signal itself (see RunObserver).
    const Resampler* resampler() const override { return resampler_.get(); }
    void begin_segment(long step, long first_sample) override;
    void end_segment(long last_sample) override;
    void band_samples(long first_sample, std::span<const double> u, std::span<const double> velocity) override;
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
    void drain(bool flush);
    void place(long sample, const double* frame);  // one output frame at its sample index
    void write_channel(std::size_t point);

    std::vector<std::filesystem::path> paths_;
    double rate_;
    AudioSignal signal_;
    AudioFades fades_;
    std::vector<double> full_scale_;
    std::unique_ptr<Resampler> resampler_;
    std::vector<double> input_;   // interleaved, one frame per time step
    std::vector<double> block_;   // interleaved resampler output
    long segment_sample_ = 0;     // sample index of the current segment's next output frame
    long keep_from_ = 0;          // the segment's outputs before this sample are dropped
    std::vector<std::vector<double>> channels_;
};

}  // namespace fretbuzz
