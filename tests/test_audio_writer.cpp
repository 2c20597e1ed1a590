// Audio files: one WAV per observation point at the requested rate, the velocity on
// request, and names that say which point each file is.
#include <gtest/gtest.h>
#include <sndfile.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <numbers>
#include <numeric>
#include <unistd.h>
#include <vector>

#include "TestSupport.hpp"
#include "fretbuzz/output/AudioWriter.hpp"
#include "fretbuzz/output/PickupHighPass.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/run/Simulation.hpp"

namespace fretbuzz {
namespace {

namespace fs = std::filesystem;

TEST(AudioFileNames, FirstPointIsAudioWavOthersCarryTheirPosition) {
    const std::vector<double> points{0.854, 0.5, 0.25, 0.5};
    EXPECT_EQ(audio_file_names(AudioSignal::displacement, points),
              (std::vector<std::string>{"audio.wav", "audio_0.5m.wav", "audio_0.25m.wav", "audio_0.5m_4.wav"}));
    EXPECT_EQ(audio_file_names(AudioSignal::velocity, std::vector<double>{0.854, 0.3}),
              (std::vector<std::string>{"velocity.wav", "velocity_0.3m.wav"}));
}

double rms(const std::vector<double>& v) {
    return std::sqrt(std::inner_product(v.begin(), v.end(), v.begin(), 0.0) / static_cast<double>(v.size()));
}

// 24-bit mono PCM WAV: a 44-byte header, 3 bytes a sample, the data padded to an even size.
std::uintmax_t wav_file_size(std::size_t samples) { return 44 + 3 * samples + (3 * samples) % 2; }

TEST(AudioWriter, WritesOneFilePerPointAtEachSupportedRate) {
    Case c = load_case("bass-pop");
    c.run.sample_rate_hz = 400000.0;
    c.run.duration_s = 0.01;
    c.observation_points_m = {0.854, 0.4};
    const fs::path dir = fs::temp_directory_path() / ("fretbuzz-audio-test-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    for (const double rate : {44100.0, 48000.0, 96000.0}) {
        SCOPED_TRACE(rate);
        std::vector<fs::path> u_paths, v_paths;
        for (const auto& name : audio_file_names(AudioSignal::displacement, c.observation_points_m)) u_paths.push_back(dir / name);
        for (const auto& name : audio_file_names(AudioSignal::velocity, c.observation_points_m)) v_paths.push_back(dir / name);
        AudioWriter displacement(u_paths, rate);
        AudioWriter velocity(v_paths, rate, AudioSignal::velocity);
        RunObserver* observers[] = {&displacement, &velocity};
        simulate(c, observers);
        const auto expected = static_cast<std::size_t>(std::llround(c.run.duration_s * rate)) + 1;
        for (std::size_t p = 0; p < 2; ++p) {
            EXPECT_NEAR(static_cast<double>(displacement.samples(p).size()), static_cast<double>(expected), 1.0);
            EXPECT_EQ(velocity.samples(p).size(), displacement.samples(p).size());
            EXPECT_EQ(fs::file_size(u_paths[p]), wav_file_size(displacement.samples(p).size()));
            EXPECT_EQ(fs::file_size(v_paths[p]), wav_file_size(velocity.samples(p).size()));
        }
        // Different points and different signals are different sounds.
        EXPECT_NE(displacement.samples(0), displacement.samples(1));
        EXPECT_GT(rms(velocity.samples(0)), 100.0 * rms(displacement.samples(0)));  // m/s vs m, at audio frequencies
    }
    fs::remove_all(dir);
}

// A mono file as libsndfile reads it: its format, rate, and samples as doubles and as integers.
struct ReadBack {
    SF_INFO info{};
    std::vector<double> samples;
    std::vector<int> integers;  // (left-justified in 32 bits)
};

ReadBack read_back(const fs::path& path) {
    ReadBack r;
    SNDFILE* f = sf_open(path.c_str(), SFM_READ, &r.info);
    EXPECT_NE(f, nullptr) << path << ": " << sf_strerror(nullptr);
    if (f == nullptr) return r;
    r.samples.resize(static_cast<std::size_t>(r.info.frames));
    r.integers.resize(r.samples.size());
    EXPECT_EQ(sf_read_double(f, r.samples.data(), r.info.frames), r.info.frames);
    sf_seek(f, 0, SEEK_SET);
    EXPECT_EQ(sf_read_int(f, r.integers.data(), r.info.frames), r.info.frames);
    sf_close(f);
    return r;
}

// FLAC by its extension (any case): read back by libsndfile as FLAC of the sample size asked
// for, at the rate, with every sample: the integers of the WAV of that size (FLAC is
// lossless), each within its quantisation of the high-passed, normalised signal.
TEST(AudioWriter, WritesFlacOfTheSampleSizeAskedFor) {
    const testing::ScratchDir scratch("flac");
    const double rate = 44100.0;
    std::vector<double> x(30001);
    for (std::size_t k = 0; k < x.size(); ++k) {
        const double t = static_cast<double>(k) / rate;
        x[k] = 1e-3 * std::exp(-3.0 * t) *
               (std::sin(2.0 * std::numbers::pi * 110.0 * t) + 0.3 * std::sin(2.0 * std::numbers::pi * 2345.0 * t));
    }
    for (const int bits : {16, 24}) {
        const fs::path wav = scratch.path() / "take.wav";
        write_normalised_audio(wav, x, rate, bits);
        const ReadBack pcm = read_back(wav);
        for (const char* name : {"take.flac", "TAKE.FLAC"}) {
            SCOPED_TRACE(std::string(name) + ", " + std::to_string(bits) + " bits");
            const fs::path path = scratch.path() / name;
            const double full_scale = write_normalised_audio(path, x, rate, bits);
            const ReadBack flac = read_back(path);
            EXPECT_EQ(flac.info.format & SF_FORMAT_TYPEMASK, SF_FORMAT_FLAC);
            EXPECT_EQ(flac.info.format & SF_FORMAT_SUBMASK, bits == 16 ? SF_FORMAT_PCM_16 : SF_FORMAT_PCM_24);
            EXPECT_EQ(flac.info.samplerate, 44100);
            EXPECT_EQ(flac.info.channels, 1);
            ASSERT_EQ(flac.samples.size(), x.size());
            EXPECT_EQ(flac.integers, pcm.integers);
            // libsndfile writes v (2^(b-1) - 1) rounded and reads n / 2^(b-1): within a step
            // and a half of full scale.
            PickupHighPass pickup(rate);
            const double step = std::ldexp(1.0, 1 - bits);
            double worst = 0.0, peak = 0.0;
            for (std::size_t k = 0; k < x.size(); ++k) {
                worst = std::max(worst, std::abs(flac.samples[k] - pickup(x[k]) / full_scale));
                peak = std::max(peak, std::abs(flac.samples[k]));
            }
            EXPECT_LE(worst, 1.5 * step) << worst / step << " steps";
            EXPECT_NEAR(peak, 0.99, 1.5 * step);
        }
    }
}

}  // namespace
}  // namespace fretbuzz
