#pragma once
// Audio of the second polarisation: the displacement along y, or along a pickup direction
// at an angle a from z (cos(a) u_z + sin(a) u_y), one WAV per observation point, through an
// AudioWriter that asks the run for that direction (same band limit, resampling and
// normalisation as audio.wav).
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "fretbuzz/output/AudioWriter.hpp"

namespace fretbuzz {

class PolarisedAudio : public AudioWriter {
public:
    // angle_deg = 90: y alone. File names: "<stem>.wav", "<stem>_<x>m.wav" (see audio_file_names).
    PolarisedAudio(std::vector<std::filesystem::path> paths, double audio_rate_hz, double angle_deg, AudioFades fades)
        : AudioWriter(std::move(paths), audio_rate_hz, AudioSignal::displacement, fades, angle_deg) {}
    const AudioWriter& writer() const { return *this; }
};

// The names of those files for the observation points: "audio.wav" -> "<stem>.wav" etc.
std::vector<std::string> polarised_audio_file_names(const std::string& stem, std::span<const double> points_m);

}  // namespace fretbuzz
