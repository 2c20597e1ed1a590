#pragma once
// Audio of the second polarisation: the displacement along y, or along a pickup direction
// at an angle a from z (cos(a) u_z + sin(a) u_y), one WAV per observation point, through an
// AudioWriter of its own (same band limit, resampling and normalisation as audio.wav).
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "fretbuzz/output/AudioWriter.hpp"

namespace fretbuzz {

class PolarisedAudio : public RunObserver {
public:
    // angle_deg = 90: y alone. File names: "<stem>.wav", "<stem>_<x>m.wav" (see audio_file_names).
    PolarisedAudio(std::vector<std::filesystem::path> paths, double audio_rate_hz, double angle_deg, AudioFades fades);

    void begin(const RunLayout& layout) override { writer_.begin(layout); }
    bool wants_every_step() const override { return true; }
    double every_step_band_hz() const override { return writer_.every_step_band_hz(); }
    void every_step_y(std::span<const double> y) override { y_.assign(y.begin(), y.end()); }
    void every_step(std::span<const double> u, std::span<const double> velocity) override;
    void finish(const RunSummary& summary) override { writer_.finish(summary); }
    const AudioWriter& writer() const { return writer_; }

private:
    AudioWriter writer_;
    double along_z_, along_y_;
    std::vector<double> y_, mixed_;
};

// The names of those files for the observation points: "audio.wav" -> "<stem>.wav" etc.
std::vector<std::string> polarised_audio_file_names(const std::string& stem, std::span<const double> points_m);

}  // namespace fretbuzz
