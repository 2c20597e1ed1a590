#include "fretbuzz/output/PolarisedAudio.hpp"

#include <cmath>
#include <numbers>

namespace fretbuzz {

PolarisedAudio::PolarisedAudio(std::vector<std::filesystem::path> paths, double audio_rate_hz, double angle_deg,
                               AudioFades fades)
    : writer_(std::move(paths), audio_rate_hz, AudioSignal::displacement, fades) {
    const double a = angle_deg * std::numbers::pi / 180.0;
    // Exactly y alone at 90 degrees (cos would leave 6e-17 of z).
    along_z_ = std::fmod(angle_deg, 90.0) == 0.0 ? std::round(std::cos(a)) : std::cos(a);
    along_y_ = std::fmod(angle_deg, 90.0) == 0.0 ? std::round(std::sin(a)) : std::sin(a);
}

void PolarisedAudio::every_step(std::span<const double> u, std::span<const double>) {
    mixed_.resize(u.size());
    for (std::size_t p = 0; p < u.size(); ++p) mixed_[p] = along_z_ * u[p] + along_y_ * (p < y_.size() ? y_[p] : 0.0);
    writer_.every_step(mixed_, {});
}

std::vector<std::string> polarised_audio_file_names(const std::string& stem, std::span<const double> points_m) {
    std::vector<std::string> names = audio_file_names(AudioSignal::displacement, points_m);
    for (std::string& name : names) name = stem + name.substr(5);  // "audio..." -> "<stem>..."
    return names;
}

}  // namespace fretbuzz
