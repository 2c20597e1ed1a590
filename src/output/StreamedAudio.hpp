#pragma once
// One mono sound written without keeping it in memory (a strings run's bridge and pickups, for
// runs of any length): each sample passes the pickup's high-pass as it comes (PickupHighPass,
// as write_normalised_audio's), its peak is tracked, and the samples wait in a scratch file
// inside the output's staging folder, unlinked as soon as it is open, so that nothing of it
// outlives the process. write() then makes the peak-normalised file, the same bytes as
// write_normalised_audio of the whole signal. Defined in AudioWriter.cpp.
#include <cstddef>
#include <filesystem>
#include <vector>

#include "../FileDescriptor.hpp"
#include "fretbuzz/output/PickupHighPass.hpp"

namespace fretbuzz {

class StreamedAudio {
public:
    // Throws runtime_error naming `scratch` if it cannot be created.
    StreamedAudio(const std::filesystem::path& scratch, double rate_hz);

    void push(double x);
    // The file (WAV, FLAC or Ogg Vorbis by its extension) of every sample pushed so far; may be
    // called for several files. Returns what full scale stands for.
    double write(const std::filesystem::path& path, int bits = 24);

private:
    void spill();  // the block to the scratch file

    std::filesystem::path scratch_;
    PickupHighPass pickup_;
    double rate_;
    FileDescriptor fd_;
    double peak_ = 0.0;
    std::size_t count_ = 0;  // samples in the scratch file
    std::vector<double> block_;
};

}  // namespace fretbuzz
