#pragma once
// A recording to analyse: one channel of a WAV (RIFF, RIFX, RF64), FLAC or AIFF file, any
// rate and sample format, read by libsndfile as doubles scaled to full scale 1.
// Someone else's file: only regular files are read, their size is checked before reading,
// the header's frame count is never trusted (buffers grow with what is decoded) and the
// length analysed is capped.
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace fretbuzz {

struct Recording {
    std::vector<double> samples;
    double rate_hz = 0.0;
    std::size_t channels = 0;  // in the file
};

struct RecordingLimits {
    double max_seconds = 30.0;                 // a string's decay: a few seconds to tens
    double max_rate_hz = 384000.0;
    std::size_t max_file_bytes = 256u << 20;   // 30 s of 8 channels of 32-bit samples at 96 kHz is 92 MB
};

// channel counts from 1. Throws InputError, naming the file, if it is missing, not a
// regular file, larger than the limit, not audio of those formats, longer than the limit,
// at a rate above it, or has no such channel.
Recording read_recording(const std::filesystem::path& path, std::size_t channel = 1,
                         const RecordingLimits& limits = {});
// The same from the file's bytes (name: for the messages).
Recording decode_recording(std::string_view bytes, const std::string& name, std::size_t channel = 1,
                           const RecordingLimits& limits = {});

}  // namespace fretbuzz
