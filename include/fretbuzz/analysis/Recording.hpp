#pragma once
// A recording to analyse: one channel of any file libsndfile reads (WAV, FLAC, AIFF, ...,
// any rate and sample format), as doubles scaled to full scale 1.
#include <cstddef>
#include <filesystem>
#include <vector>

namespace fretbuzz {

struct Recording {
    std::vector<double> samples;
    double rate_hz = 0.0;
    std::size_t channels = 0;  // in the file
};

// channel counts from 1. Throws InputError if the file is not audio libsndfile can read,
// or the channel is not in 1..channels.
Recording read_recording(const std::filesystem::path& path, std::size_t channel = 1);

}  // namespace fretbuzz
