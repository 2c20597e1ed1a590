#include "fretbuzz/output/PolarisedAudio.hpp"

namespace fretbuzz {

std::vector<std::string> polarised_audio_file_names(const std::string& stem, std::span<const double> points_m) {
    std::vector<std::string> names = audio_file_names(AudioSignal::displacement, points_m);
    for (std::string& name : names) name = stem + name.substr(5);  // "audio..." -> "<stem>..."
    return names;
}

}  // namespace fretbuzz
