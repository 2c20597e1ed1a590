#include "fretbuzz/output/AudioWriter.hpp"

#include <fcntl.h>
#include <sndfile.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <numbers>
#include <set>
#include <stdexcept>
#include <utility>

#include "../FileDescriptor.hpp"
#include "StreamedAudio.hpp"
#include "fretbuzz/output/CsvWriters.hpp"
#include "fretbuzz/output/PickupHighPass.hpp"

namespace fretbuzz {

namespace {
constexpr std::size_t kBlockFrames = 1 << 14;
}  // namespace

std::vector<std::string> audio_file_names(AudioSignal signal, std::span<const double> points_m) {
    const std::string stem = signal == AudioSignal::velocity ? "velocity" : "audio";
    std::vector<std::string> names;
    std::set<std::string> taken;
    for (std::size_t p = 0; p < points_m.size(); ++p) {
        std::string name = stem;
        if (p > 0) {
            name += '_';
            append_number(name, points_m[p]);
            name += 'm';
        }
        // The same point observed twice still gets a file of its own.
        if (taken.contains(name)) name.append("_").append(std::to_string(p + 1));
        taken.insert(name);
        names.push_back(name + ".wav");
    }
    return names;
}

AudioWriter::AudioWriter(std::vector<std::filesystem::path> paths, double audio_rate_hz, AudioSignal signal,
                         AudioFades fades, double angle_deg)
    : paths_(std::move(paths)), rate_(audio_rate_hz), signal_(signal), fades_(fades), angle_(angle_deg) {
    if (!(fades_.in_s >= 0.0 && fades_.out_s >= 0.0))
        throw std::invalid_argument("AudioWriter: fades must be >= 0 s");
}

void AudioWriter::begin(const RunLayout& layout) {
    const std::size_t points = layout.observation_points_m.size();
    if (paths_.size() != points)
        throw std::logic_error("AudioWriter: " + std::to_string(paths_.size()) + " file paths for " +
                               std::to_string(points) + " observation points");
    channels_.assign(points, {});
    const auto expected = static_cast<std::size_t>(static_cast<double>(layout.steps) * layout.dt * rate_) + 16;
    for (auto& channel : channels_) channel.reserve(expected);
}

void AudioWriter::audio(long first_sample, std::span<const double> samples) {
    const std::size_t width = channels_.size();
    if (width == 0 || static_cast<std::size_t>(first_sample) != channels_[0].size())
        throw std::logic_error("AudioWriter: audio samples out of order");
    for (std::size_t f = 0; f < samples.size() / width; ++f)
        for (std::size_t p = 0; p < width; ++p) channels_[p].push_back(samples[f * width + p]);
}

void AudioWriter::finish(const RunSummary&) {
    full_scale_.assign(channels_.size(), 1.0);
    for (std::size_t p = 0; p < channels_.size(); ++p) write_channel(p);
}

void AudioWriter::write_channel(std::size_t point) {
    // Fades first, so that the peak (and the gain) is that of the file as heard. Applied on
    // the way out rather than to a copy: a long run's channel is megabytes of fresh pages.
    const std::vector<double>& x = channels_[point];
    const auto samples = [&](double seconds) {
        return std::min(x.size(), static_cast<std::size_t>(std::llround(seconds * rate_)));
    };
    full_scale_[point] = write_faded_audio(paths_[point], x, rate_, 24, samples(fades_.in_s), samples(fades_.out_s));
}

namespace {
// The raised-cosine weight of the k-th of n faded samples, counted from the silent end.
double fade_weight(std::size_t k, std::size_t n) {
    return 0.5 - 0.5 * std::cos(std::numbers::pi * static_cast<double>(k) / static_cast<double>(n));
}

// The format the extension names (any case): Ogg Vorbis, FLAC or (any other) WAV.
int format_of(const std::filesystem::path& path, int bits) {
    std::string extension = path.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    const int pcm = bits == 16 ? SF_FORMAT_PCM_16 : SF_FORMAT_PCM_24;
    if (extension == ".ogg") return SF_FORMAT_OGG | SF_FORMAT_VORBIS;
    if (extension == ".flac") return SF_FORMAT_FLAC | pcm;
    return SF_FORMAT_WAV | pcm;
}
}  // namespace

namespace {
// Writes a signal, block by block as `fill` gives it (n values from `first`, already scaled),
// as `path`'s extension names; libsndfile's error, the disk's or the close's named with it.
template <class Fill>
void write_blocks(const std::filesystem::path& path, std::size_t size, double rate_hz, int bits, double vbr_quality,
                  Fill&& fill) {
    SF_INFO info{};
    info.samplerate = static_cast<int>(std::lround(rate_hz));
    info.channels = 1;
    info.format = format_of(path, bits);
    // Opened by the system and handed to libsndfile: libsndfile keeps a path it opens in a
    // buffer of its own (about 1 kB), and only the kernel's limits (checked up front) apply.
    FileDescriptor fd(::open(path.c_str(), O_CREAT | O_WRONLY | O_TRUNC | O_CLOEXEC, 0666));
    if (fd.get() < 0) throw std::runtime_error("cannot write " + path.string() + ": " + std::strerror(errno));
    SNDFILE* file = sf_open_fd(fd.get(), SFM_WRITE, &info, SF_FALSE);
    if (file == nullptr) throw std::runtime_error("cannot write " + path.string() + ": " + sf_strerror(nullptr));
    if (vbr_quality >= 0.0) sf_command(file, SFC_SET_VBR_ENCODING_QUALITY, &vbr_quality, sizeof vbr_quality);
    std::vector<double> block(std::min(size, kBlockFrames));
    std::string write_error;
    for (std::size_t first = 0; first < size && write_error.empty(); first += block.size()) {
        const std::size_t n = std::min(block.size(), size - first);
        fill(first, std::span<double>(block.data(), n));
        if (sf_write_double(file, block.data(), static_cast<sf_count_t>(n)) != static_cast<sf_count_t>(n))
            write_error = sf_strerror(file);
    }
    // sf_close writes the header's final sizes: a full disk can fail it alone.
    const int close_error = sf_close(file);
    if (!write_error.empty()) throw std::runtime_error("cannot write " + path.string() + ": " + write_error);
    if (close_error != 0) throw std::runtime_error("cannot write " + path.string() + ": " + sf_error_number(close_error));
    if (fd.close() != 0) throw std::runtime_error("cannot write " + path.string() + ": " + std::strerror(errno));
}

double write_audio(const std::filesystem::path& path, std::span<const double> signal, double rate_hz, int bits,
                   std::size_t fade_in, std::size_t fade_out, double vbr_quality) {
    const std::size_t size = signal.size();
    // What a pickup passes (no DC), then the fades, then the peak: the gain is that of the
    // file as heard. Taken twice in the same order (once for the peak, once to write) rather
    // than kept: a long run's channel is megabytes of fresh pages.
    const auto faded = [&](PickupHighPass& pickup, std::size_t i) {
        double v = pickup(signal[i]);
        if (i < fade_in) v *= fade_weight(i, fade_in);
        if (size - i <= fade_out) v *= fade_weight(size - 1 - i, fade_out);
        return v;
    };
    double peak = 0.0;
    PickupHighPass pickup(rate_hz);
    for (std::size_t i = 0; i < size; ++i) peak = std::max(peak, std::abs(faded(pickup, i)));
    const double gain = peak > 0.0 ? 0.99 / peak : 1.0;
    pickup = PickupHighPass(rate_hz);
    write_blocks(path, size, rate_hz, bits, vbr_quality, [&](std::size_t first, std::span<double> block) {
        for (std::size_t k = 0; k < block.size(); ++k) block[k] = faded(pickup, first + k) * gain;
    });
    return 1.0 / gain;
}
}  // namespace

double write_faded_audio(const std::filesystem::path& path, std::span<const double> signal, double rate_hz, int bits,
                         std::size_t fade_in, std::size_t fade_out) {
    return write_audio(path, signal, rate_hz, bits, fade_in, fade_out, -1.0);
}

void write_compact_audio(const std::filesystem::path& path, std::span<const double> signal, double rate_hz,
                         double quality) {
    if (!(quality >= 0.0 && quality <= 1.0))
        throw std::invalid_argument("write_compact_audio: the quality must be in [0, 1]");
    write_audio(path.extension() == ".ogg" ? path : std::filesystem::path(path).concat(".ogg"), signal, rate_hz, 16, 0,
                0, quality);
}

double write_normalised_audio(const std::filesystem::path& path, std::span<const double> signal, double rate_hz,
                              int bits) {
    return write_faded_audio(path, signal, rate_hz, bits, 0, 0);
}

StreamedAudio::StreamedAudio(const std::filesystem::path& scratch, double rate_hz)
    : scratch_(scratch),
      pickup_(rate_hz),
      rate_(rate_hz),
      fd_(::open(scratch.c_str(), O_CREAT | O_EXCL | O_RDWR | O_CLOEXEC | O_NOFOLLOW, 0600)) {
    if (fd_.get() < 0) throw std::runtime_error("cannot write " + scratch.string() + ": " + std::strerror(errno));
    // Named only while it is opened: removed at once, it goes with its descriptor, whatever
    // ends the process.
    ::unlink(scratch.c_str());
    block_.reserve(kBlockFrames);
}

void StreamedAudio::push(double x) {
    const double v = pickup_(x);
    peak_ = std::max(peak_, std::abs(v));
    block_.push_back(v);
    if (block_.size() == kBlockFrames) spill();
}

void StreamedAudio::spill() {
    if (const int error = write_fully(fd_.get(), block_.data(), block_.size() * sizeof(double)); error != 0)
        throw std::runtime_error("cannot write " + scratch_.string() + ": " + std::strerror(error));
    count_ += block_.size();
    block_.clear();
}

double StreamedAudio::write(const std::filesystem::path& path, int bits) {
    if (!block_.empty()) spill();
    const double gain = peak_ > 0.0 ? 0.99 / peak_ : 1.0;
    write_blocks(path, count_, rate_, bits, -1.0, [&](std::size_t first, std::span<double> block) {
        const int error = read_fully_at(fd_.get(), block.data(), block.size() * sizeof(double),
                                        static_cast<off_t>(first * sizeof(double)));
        if (error != 0) throw std::runtime_error("cannot read back " + scratch_.string() + ": " + std::strerror(error));
        for (double& v : block) v *= gain;
    });
    return 1.0 / gain;
}

}  // namespace fretbuzz
