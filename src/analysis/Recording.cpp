#include "fretbuzz/analysis/Recording.hpp"

#include <sndfile.h>

#include <memory>
#include <string>

#include "fretbuzz/Error.hpp"

namespace fretbuzz {

Recording read_recording(const std::filesystem::path& path, std::size_t channel) {
    SF_INFO info{};
    const std::unique_ptr<SNDFILE, int (*)(SNDFILE*)> file(sf_open(path.c_str(), SFM_READ, &info), sf_close);
    if (!file)
        throw InputError("RECORDING " + path.string() + ": not an audio file libsndfile can read (" +
                         sf_strerror(nullptr) + "); give a WAV, FLAC, AIFF or similar file");
    const auto channels = static_cast<std::size_t>(info.channels);
    if (channel < 1 || channel > channels)
        throw InputError("--channel " + std::to_string(channel) + ": must be in 1.." + std::to_string(channels) +
                         " (" + path.string() + " has " + std::to_string(channels) + " channel(s))");
    std::vector<double> interleaved(static_cast<std::size_t>(info.frames) * channels);
    sf_command(file.get(), SFC_SET_NORM_DOUBLE, nullptr, SF_TRUE);
    const sf_count_t read = sf_readf_double(file.get(), interleaved.data(), info.frames);
    Recording r;
    r.rate_hz = info.samplerate;
    r.channels = channels;
    r.samples.reserve(static_cast<std::size_t>(read));
    for (sf_count_t i = 0; i < read; ++i)
        r.samples.push_back(interleaved[static_cast<std::size_t>(i) * channels + channel - 1]);
    return r;
}

}  // namespace fretbuzz
