#include "fretbuzz/analysis/Recording.hpp"

#include <sndfile.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>
#include <sstream>
#include <system_error>
#include <vector>

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

// The other way: v's low `bytes` bytes written at `out`.
void write_uint(char* out, std::uint64_t v, std::size_t bytes, bool big_endian) {
    for (std::size_t i = 0; i < bytes; ++i) out[big_endian ? bytes - 1 - i : i] = static_cast<char>((v >> (8 * i)) & 0xffu);
}

std::string printable(std::string_view tag) {
    std::string out(tag);
    for (char& c : out)
        if (c < 0x20 || c > 0x7e) c = '?';
    return out;
}

// RIFF-style containers (WAV, RF64, AIFF) are walked chunk by chunk before libsndfile sees
// them, and only the chunks that say how to read the audio reach it: the format, the audio
// data and what they need (frame count, RF64 sizes, AIFF-C version). libsndfile 1.2 parses
// metadata chunks (LIST, cue, smpl, acid...) with sizes it does not check: a 213-byte RF64
// file whose LIST chunk runs far past the end of the file, or a LIST whose INFO entry claims
// 2^32 - 9 bytes, keeps it jumping back and forth for ever. fretbuzz reads none of that
// metadata. Every chunk must lie inside the file, except the audio data, which may end early:
// a recording cut short is still read.
struct Chunk {
    std::string_view tag;
    std::size_t at = 0;      // where its 8-byte header starts
    std::uint64_t size = 0;  // as declared
};

std::string chunk_refusal(const std::string& what, const Chunk& c, const std::string& problem) {
    return what + ": its '" + printable(c.tag) + "' chunk at byte " + std::to_string(c.at) + " " + problem +
           ": a damaged file";
}

// The parts of the file libsndfile is given: the container's 12-byte header (its size field
// set to what follows), then the chunks kept, in the file's order, each of a size its parser
// reads exactly: where a parser stops short, libsndfile parses the rest of the chunk as
// chunks. RF64's ds64 chunk is given in its 28-byte form (no size table), with its data
// length cut to what the file holds: libsndfile seeks past the audio by it, and a length of
// 2^63 or more is a seek backwards, into chunks it would parse again for ever.
// Built in place: the pieces point into it.
class SplicedFile {
public:
    SplicedFile(std::string_view b, const std::string& what);
    SplicedFile(const SplicedFile&) = delete;
    SplicedFile& operator=(const SplicedFile&) = delete;

    std::vector<std::string_view> pieces;
    std::size_t size = 0;

private:
    std::array<char, 12> head_{};
    std::array<char, 36> ds64_{};
};

SplicedFile::SplicedFile(std::string_view b, const std::string& what) {
    const std::string_view container = b.substr(0, 4);
    const bool big_endian = container == "RIFX" || container == "FORM";
    const bool rf64 = container == "RF64";
    const bool aiff = container == "FORM";
    const std::string_view audio = aiff ? "SSND" : "data";
    // What libsndfile needs to read the samples; each tag once (the first).
    const std::array<std::string_view, 4> kept = aiff ? std::array<std::string_view, 4>{"COMM", "SSND", "FVER", ""}
                                                      : std::array<std::string_view, 4>{"fmt ", "data", "fact", "ds64"};
    // Smallest sizes for which libsndfile's parsers of these chunks stay inside them.
    const auto smallest = [](std::string_view tag) -> std::uint64_t {
        if (tag == "fmt ") return 16;
        if (tag == "fact" || tag == "FVER") return 4;
        if (tag == "ds64") return 28;
        if (tag == "COMM") return 18;
        if (tag == "SSND") return 8;
        return 0;
    };
    // The COMM parser reads 18, 22, or 24 bytes and a name of up to 255 (its size made even).
    const auto comm_read_whole = [](std::uint64_t bytes) {
        bytes += bytes & 1;
        return bytes == 18 || bytes == 22 || (bytes >= 24 && bytes <= 24 + 256);
    };
    std::copy_n(b.data(), head_.size(), head_.begin());
    pieces.emplace_back(head_.data(), head_.size());
    std::vector<std::string_view> seen;
    std::optional<std::uint64_t> rf64_data_bytes;  // from the ds64 chunk
    for (std::size_t at = 12; at + 8 <= b.size();) {
        Chunk c{b.substr(at, 4), at, read_u32(b, at + 4, big_endian)};
        const std::size_t left = b.size() - at - 8;
        const bool wanted = std::find(kept.begin(), kept.end(), c.tag) != kept.end() && !c.tag.empty() &&
                            (c.tag != "ds64" || rf64) && std::find(seen.begin(), seen.end(), c.tag) == seen.end();
        if (wanted && c.size < smallest(c.tag))
            throw InputError(chunk_refusal(what, c, "holds " + std::to_string(c.size) + " bytes, fewer than the " +
                                                        std::to_string(smallest(c.tag)) + " it must"));
        if (wanted && c.tag == "COMM" && !comm_read_whole(c.size))
            throw InputError(chunk_refusal(what, c, "holds " + std::to_string(c.size) +
                                                        " bytes: a COMM chunk holds 18, 22, or 24 to 280"));
        if (wanted && c.tag == "ds64" && left >= 28)
            rf64_data_bytes = read_u32(b, at + 16, false) | (read_u32(b, at + 20, false) << 32);
        // A WAV file left unclosed by its recorder (RIFF size 8, data size 0): its data runs to
        // the end, as libsndfile reads it.
        if (!rf64 && !aiff && c.tag == audio && c.size == 0 && read_u32(b, 4, big_endian) == 8) c.size = left;
        // RF64's audio data is as long as its ds64 chunk says, whatever its own size field
        // (libsndfile reads it so, and parses what follows as chunks).
        if (rf64 && c.tag == audio) c.size = rf64_data_bytes ? *rf64_data_bytes : c.size == 0xffffffffu ? 0 : c.size;
        const bool audio_to_end = c.tag == audio && c.size > left;
        if (c.size > left && !audio_to_end)
            throw InputError(chunk_refusal(what, c, "claims " + std::to_string(c.size) +
                                                        " bytes, past the end of the file (" + std::to_string(b.size()) +
                                                        " bytes)"));
        if (wanted) seen.push_back(c.tag);
        if (wanted && c.tag == audio && rf64_data_bytes) {
            // the ds64 given says what the file holds
            const std::uint64_t held = std::min<std::uint64_t>(c.size, left);
            write_uint(ds64_.data() + 16, held, 8, false);
        }
        const std::size_t extent =
            audio_to_end ? b.size() - at : 8 + static_cast<std::size_t>(c.size) + static_cast<std::size_t>(c.size & 1);
        if (wanted && c.tag == "ds64") {
            std::copy_n(b.data() + at, ds64_.size() - 4, ds64_.begin());
            write_uint(ds64_.data() + 4, 28, 4, false);
            write_uint(ds64_.data() + 32, 0, 4, false);  // no table
            pieces.emplace_back(ds64_.data(), ds64_.size());
        } else if (wanted) {
            pieces.push_back(b.substr(at, extent));  // (a missing pad byte at the end: cut short)
        }
        if (audio_to_end) break;
        at += extent;
    }
    for (const std::string_view piece : pieces) size += piece.size();
    // The container's size field: what follows it (RF64 keeps its 0xffffffff, its ds64 says).
    if (!rf64) {
        const auto rest = static_cast<std::uint32_t>(std::min<std::size_t>(size - 8, 0xffffffffu));
        write_uint(head_.data() + 4, rest, 4, big_endian);
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

// libsndfile reads from memory through its virtual I/O: the file's bytes, or the pieces of a
// spliced one, back to back.
struct MemoryFile {
    std::vector<std::string_view> pieces;
    sf_count_t size = 0;
    sf_count_t position = 0;
};

sf_count_t memory_length(void* user) { return static_cast<MemoryFile*>(user)->size; }

sf_count_t memory_seek(sf_count_t offset, int whence, void* user) {
    auto& file = *static_cast<MemoryFile*>(user);
    const sf_count_t base = whence == SEEK_CUR ? file.position : whence == SEEK_END ? file.size : 0;
    // Positions past the end read nothing; before the start, or absurdly far, they are refused.
    const sf_count_t limit = file.size + (sf_count_t{1} << 40);
    if (offset < -base || offset > limit - base) return -1;
    file.position = base + offset;
    return file.position;
}

sf_count_t memory_read(void* destination, sf_count_t count, void* user) {
    auto& file = *static_cast<MemoryFile*>(user);
    auto* out = static_cast<char*>(destination);
    sf_count_t done = 0, start = 0;
    for (const std::string_view piece : file.pieces) {
        const auto length = static_cast<sf_count_t>(piece.size());
        if (done < count && file.position < start + length) {
            const sf_count_t from = file.position - start;
            const sf_count_t n = std::min(count - done, length - from);
            std::memcpy(out + done, piece.data() + from, static_cast<std::size_t>(n));
            done += n;
            file.position += n;
        }
        start += length;
    }
    return done;
}

sf_count_t memory_write(const void*, sf_count_t, void*) { return 0; }

sf_count_t memory_tell(void* user) { return static_cast<MemoryFile*>(user)->position; }

}  // namespace

Recording decode_recording(std::string_view bytes, const std::string& name, std::size_t channel,
                           const RecordingLimits& limits) {
    const std::string what = "recording " + name;
    if (!known_container(bytes))
        throw InputError(what + ": not a WAV, FLAC or AIFF file (convert it, e.g. `sox in.ogg out.wav`)");
    MemoryFile memory;
    std::optional<SplicedFile> spliced;
    if (bytes.substr(0, 4) == "fLaC") {
        memory.pieces = {bytes};
        memory.size = static_cast<sf_count_t>(bytes.size());
    } else {
        spliced.emplace(bytes, what);
        memory.pieces = spliced->pieces;
        memory.size = static_cast<sf_count_t>(spliced->size);
    }
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
    // libsndfile reads an AIFF rate past 2^258 (inf among them) as 0x4000000 Hz.
    const bool huge = (info.format & SF_FORMAT_TYPEMASK) == SF_FORMAT_AIFF && info.samplerate == 0x4000000;
    const double rate = huge ? HUGE_VAL : info.samplerate;
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
