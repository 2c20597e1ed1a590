#include "fretbuzz/analysis/Recording.hpp"

#include <sndfile.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <sstream>
#include <system_error>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/TextFile.hpp"

namespace fretbuzz {

namespace {

std::string cut_advice(const RecordingLimits& limits) {
    const std::string seconds = number_text(limits.max_seconds);
    return "cut the decay out first, e.g. `sox in.wav out.wav trim 0 " + seconds + "` or `ffmpeg -i in.wav -t " +
           seconds + " out.wav` (`remix 1` or `-ac 1` keeps one channel)";
}

// Only the containers a recorder writes: libsndfile reads some twenty formats, and each
// decoder it runs on someone else's bytes is one more place for a malformed file to hit.
bool known_container(std::string_view b) {
    const auto at = [&b](std::size_t offset, std::string_view tag) { return b.substr(offset, tag.size()) == tag; };
    if (b.size() < 12) return at(0, "fLaC");
    return ((at(0, "RIFF") || at(0, "RIFX") || at(0, "RF64")) && at(8, "WAVE")) || at(0, "fLaC") ||
           (at(0, "FORM") && (at(8, "AIFF") || at(8, "AIFC")));
}

std::uint64_t read_u32(std::string_view b, std::size_t at, bool big_endian) {
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < 4; ++i) {
        const auto byte = static_cast<std::uint64_t>(static_cast<unsigned char>(b[at + (big_endian ? i : 3 - i)]));
        v = (v << 8) | byte;
    }
    return v;
}

std::string printable(std::string_view tag) {
    std::string out(tag);
    for (char& c : out)
        if (c < 0x20 || c > 0x7e) c = '?';
    return out;
}

// RIFF-style containers (WAV, RF64, AIFF): libsndfile's header parser can spin for minutes
// over a chunk that claims to run far past the end of the file (a 213-byte RF64 file with
// such a LIST chunk does it to libsndfile 1.2), so every chunk but the audio data must lie
// inside the file. The audio data may end early: a recording cut short is still read.
void check_chunks(std::string_view b, const std::string& what) {
    if (b.substr(0, 4) == "fLaC") return;
    const bool big_endian = b.substr(0, 4) == "RIFX" || b.substr(0, 4) == "FORM";
    const bool rf64 = b.substr(0, 4) == "RF64";
    const std::string_view audio = b.substr(0, 4) == "FORM" ? "SSND" : "data";
    std::uint64_t rf64_data_bytes = 0;  // from the ds64 chunk
    for (std::size_t at = 12; at + 8 <= b.size();) {
        const std::string_view tag = b.substr(at, 4);
        std::uint64_t size = read_u32(b, at + 4, big_endian);
        const std::size_t left = b.size() - at - 8;
        if (rf64 && tag == "ds64" && size >= 16 && left >= 16)
            rf64_data_bytes = read_u32(b, at + 16, false) | (read_u32(b, at + 20, false) << 32);
        if (tag == audio && rf64 && size == 0xffffffffu) size = rf64_data_bytes;
        if (size > left) {
            if (tag == audio) return;
            throw InputError(what + ": its '" + printable(tag) + "' chunk at byte " + std::to_string(at) + " claims " +
                             std::to_string(size) + " bytes, past the end of the file (" + std::to_string(b.size()) +
                             " bytes): a damaged file");
        }
        at += 8 + static_cast<std::size_t>(size) + static_cast<std::size_t>(size & 1);
    }
}

bool known_format(int format) {
    switch (format & SF_FORMAT_TYPEMASK) {
        case SF_FORMAT_WAV:
        case SF_FORMAT_WAVEX:
        case SF_FORMAT_RF64:
        case SF_FORMAT_FLAC:
        case SF_FORMAT_AIFF:
            return true;
        default:
            return false;
    }
}

// libsndfile reads from memory through its virtual I/O.
struct MemoryFile {
    std::string_view bytes;
    sf_count_t position = 0;
};

sf_count_t memory_length(void* user) { return static_cast<sf_count_t>(static_cast<MemoryFile*>(user)->bytes.size()); }

sf_count_t memory_seek(sf_count_t offset, int whence, void* user) {
    auto& file = *static_cast<MemoryFile*>(user);
    const auto size = static_cast<sf_count_t>(file.bytes.size());
    const sf_count_t base = whence == SEEK_CUR ? file.position : whence == SEEK_END ? size : 0;
    // Positions past the end read nothing; before the start, or absurdly far, they are refused.
    const sf_count_t limit = size + (sf_count_t{1} << 40);
    if (offset < -base || offset > limit - base) return -1;
    file.position = base + offset;
    return file.position;
}

sf_count_t memory_read(void* destination, sf_count_t count, void* user) {
    auto& file = *static_cast<MemoryFile*>(user);
    const auto size = static_cast<sf_count_t>(file.bytes.size());
    if (count <= 0 || file.position >= size) return 0;
    const sf_count_t n = std::min(count, size - file.position);
    std::memcpy(destination, file.bytes.data() + file.position, static_cast<std::size_t>(n));
    file.position += n;
    return n;
}

sf_count_t memory_write(const void*, sf_count_t, void*) { return 0; }

sf_count_t memory_tell(void* user) { return static_cast<MemoryFile*>(user)->position; }

}  // namespace

Recording decode_recording(std::string_view bytes, const std::string& name, std::size_t channel,
                           const RecordingLimits& limits) {
    const std::string what = "recording " + name;
    if (!known_container(bytes))
        throw InputError(what + ": not a WAV, FLAC or AIFF file (convert it, e.g. `sox in.ogg out.wav`)");
    check_chunks(bytes, what);
    MemoryFile memory{bytes};
    SF_VIRTUAL_IO io{memory_length, memory_seek, memory_read, memory_write, memory_tell};
    SF_INFO info{};
    const std::unique_ptr<SNDFILE, int (*)(SNDFILE*)> file(sf_open_virtual(&io, SFM_READ, &info, &memory), sf_close);
    if (!file)
        throw InputError(what + ": not audio libsndfile can read (" + sf_strerror(nullptr) +
                         "); give a WAV, FLAC or AIFF file");
    if (!known_format(info.format)) throw InputError(what + ": not a WAV, FLAC or AIFF file");
    if (info.channels < 1) throw InputError(what + ": the file declares no channel");
    const auto channels = static_cast<std::size_t>(info.channels);
    if (channel < 1 || channel > channels)
        throw InputError("--channel " + std::to_string(channel) + ": must be in 1.." + std::to_string(channels) +
                         " (" + name + " has " + std::to_string(channels) + " channel(s))");
    const double rate = info.samplerate;
    if (!(rate >= 1.0 && rate <= limits.max_rate_hz))
        throw InputError(what + ": sample rate " + number_text(rate) + " Hz: must be in [1, " + number_text(limits.max_rate_hz) +
                         "] Hz (resample it, e.g. `sox in.wav -r 96000 out.wav`)");

    // The header's frame count is a claim: read in blocks until the data ends or the cap.
    const auto max_frames = static_cast<sf_count_t>(limits.max_seconds * rate);
    constexpr sf_count_t kBlockFrames = 8192;
    std::vector<double> block(static_cast<std::size_t>(kBlockFrames) * channels);
    sf_command(file.get(), SFC_SET_NORM_DOUBLE, nullptr, SF_TRUE);
    Recording r;
    r.rate_hz = rate;
    r.channels = channels;
    sf_count_t total = 0;
    while (true) {
        const sf_count_t read = sf_readf_double(file.get(), block.data(), kBlockFrames);
        if (read <= 0) break;
        total += read;
        if (total > max_frames)
            throw InputError(what + ": longer than " + number_text(limits.max_seconds) + " s at " + number_text(rate) +
                             " Hz, the most fretbuzz estimate analyses; " + cut_advice(limits));
        for (sf_count_t i = 0; i < read; ++i)
            r.samples.push_back(block[static_cast<std::size_t>(i) * channels + channel - 1]);
    }
    if (const int error = sf_error(file.get()); error != SF_ERR_NO_ERROR)
        throw InputError(what + ": unreadable after " + std::to_string(total) + " frames (" + sf_error_number(error) +
                         ")");
    return r;
}

Recording read_recording(const std::filesystem::path& path, std::size_t channel, const RecordingLimits& limits) {
    const std::string what = "recording " + path.string();
    // Too large to be read whole: say how to cut it (read_text_file below checks again, on
    // the file it opens, and refuses what is not a regular file).
    std::error_code error;
    if (std::filesystem::is_regular_file(path, error)) {
        const auto bytes = std::filesystem::file_size(path, error);
        if (!error && bytes > limits.max_file_bytes)
            throw InputError(what + ": " + std::to_string(bytes >> 20) + " MiB, more than the " +
                             std::to_string(limits.max_file_bytes >> 20) + " MiB read; " + cut_advice(limits));
    }
    const std::string bytes = read_text_file(path, "recording", limits.max_file_bytes);
    return decode_recording(bytes, path.string(), channel, limits);
}

}  // namespace fretbuzz
