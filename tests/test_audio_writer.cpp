// Audio files: one WAV per observation point at the requested rate, the velocity on
// request, and names that say which point each file is.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <numeric>
#include <unistd.h>
#include <vector>

#include "fretbuzz/output/AudioWriter.hpp"
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

}  // namespace
}  // namespace fretbuzz
