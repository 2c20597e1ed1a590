// `fretbuzz estimate`: bad input exits 2 and writes nothing; a simulated free decay goes
// through estimate -> case.toml -> the mode table the case resolves to.
#include <gtest/gtest.h>
#include <sndfile.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <numbers>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "SyntheticDecay.hpp"
#include "TestSupport.hpp"
#include "fretbuzz/input/CaseFile.hpp"

namespace fretbuzz {
namespace {

using testing::run_cli;
using testing::ScratchDir;
namespace fs = std::filesystem;

std::string read_file(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

void write_file(const fs::path& path, const std::string& bytes) {
    std::ofstream(path, std::ios::binary) << bytes;
}

TEST(EstimateCommand, NotAudioIsRejectedAndNothingIsWritten) {
    ScratchDir dir("estimate-bad");
    const fs::path text = dir.path() / "notes.wav", out = dir.path() / "out";
    std::ofstream(text) << "this is not audio\n";
    auto r = run_cli("estimate " + text.string() + " --L 0.863 --mu 6.69e-3 --d 1.14e-3 --out " + out.string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(text.string() + ": not a WAV, FLAC or AIFF file"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(out));
    // A WAV whose chunks fit the file but whose format chunk is 4 bytes of text: refused
    // before libsndfile parses it.
    write_file(text, std::string("RIFF\x10\0\0\0WAVEfmt \x04\0\0\0text", 24));
    r = run_cli("estimate " + text.string() + " --L 0.863 --mu 6.69e-3 --d 1.14e-3 --out " + out.string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(text.string() + ": its 'fmt ' chunk at byte 12 holds 4 bytes, fewer than the 16 it must"),
              std::string::npos)
        << r.output;
    EXPECT_FALSE(fs::exists(out));
    // A whole format chunk naming a codec libsndfile does not know (0x1234): its refusal,
    // naming the file.
    write_file(text, std::string("RIFF\x2c\0\0\0WAVEfmt \x10\0\0\0\x34\x12\x01\0\x40\x1f\0\0\x80\x3e\0\0\x02\0\x10\0"
                                 "data\x08\0\0\0\1\2\3\4\5\6\7\x08",
                                 52));
    r = run_cli("estimate " + text.string() + " --L 0.863 --mu 6.69e-3 --d 1.14e-3 --out " + out.string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(text.string() + ": not audio libsndfile can read"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(out));
}

// A mono 16-bit PCM WAV file of the samples (full scale 1).
void write_wav(const fs::path& path, const std::vector<double>& x, int rate) {
    std::ofstream out(path, std::ios::binary);
    const auto u32 = [&out](std::uint32_t v) { out.write(reinterpret_cast<const char*>(&v), 4); };
    const auto u16 = [&out](std::uint16_t v) { out.write(reinterpret_cast<const char*>(&v), 2); };
    const auto bytes = static_cast<std::uint32_t>(2 * x.size());
    out.write("RIFF", 4);
    u32(36 + bytes);
    out.write("WAVEfmt ", 8);
    u32(16);
    u16(1);
    u16(1);
    u32(static_cast<std::uint32_t>(rate));
    u32(static_cast<std::uint32_t>(2 * rate));
    u16(2);
    u16(16);
    out.write("data", 4);
    u32(bytes);
    for (const double v : x) u16(static_cast<std::uint16_t>(static_cast<std::int16_t>(std::lround(32767.0 * v))));
}

// `spec`'s decay scaled to the peak `peak`.
std::vector<double> scaled(const testing::DecaySpec& spec, double peak) {
    std::vector<double> x = testing::decay_signal(spec);
    double top = 0.0;
    for (const double v : x) top = std::max(top, std::abs(v));
    for (double& v : x) v *= peak / top;
    return x;
}

// Twelve decaying partials of a stiff string at 110 Hz, `seconds` long, peak `peak`.
std::vector<double> decay(double seconds, int rate, double peak) {
    testing::DecaySpec spec;
    spec.seconds = seconds;
    spec.rate_hz = rate;
    return scaled(spec, peak);
}

TEST(EstimateCommand, BadRecordingsExitTwoAndWriteNothing) {
    ScratchDir dir("estimate-bad-recordings");
    const int rate = 16000;
    std::vector<double> clipped = decay(1.0, rate, 1.6);
    for (double& v : clipped) v = std::clamp(v, -1.0, 1.0);
    const std::vector<std::pair<std::string, std::vector<double>>> recordings = {
        {"silent", std::vector<double>(rate, 0.0)},
        {"at least 0.2 s", decay(0.1, rate, 0.5)},
        {"clipped", clipped},
    };
    for (const auto& [expected, samples] : recordings) {
        const fs::path wav = dir.path() / "in.wav", out = dir.path() / "out";
        write_wav(wav, samples, rate);
        const auto r = run_cli("estimate " + wav.string() + " --L 0.65 --mu 6e-3 --d 1.1e-3 --no-plots --out " + out.string());
        EXPECT_EQ(r.exit_code, 2) << expected << ": " << r.output;
        EXPECT_NE(r.output.find(expected), std::string::npos) << r.output;
        EXPECT_FALSE(fs::exists(out)) << expected;
    }
    // The same decay, neither clipped nor short, is accepted: the refusals are about the input.
    write_wav(dir.path() / "good.wav", decay(1.0, rate, 0.5), rate);
    const auto r = run_cli("estimate " + (dir.path() / "good.wav").string() +
                           " --L 0.65 --mu 6e-3 --d 1.1e-3 --no-plots -q --out " + (dir.path() / "good").string());
    EXPECT_EQ(r.exit_code, 0) << r.output;
}

TEST(EstimateCommand, RunEstimateAndCaseRoundTrip) {
    ScratchDir dir("estimate-trip");
    const fs::path run = dir.path() / "run", est = dir.path() / "est";
    ASSERT_EQ(run_cli("run bass-pluck --fs 48000 --allow-aliasing --duration 1.5 -q --out " + run.string()).exit_code, 0);
    const std::string wav = (run / "audio.wav").string();

    // f0 outside the analysed band: exit 2, no output directory.
    auto r = run_cli("estimate " + wav + " --case bass-pluck --d 1.14e-3 --f0 98 --band 150 4000 --no-plots --out " +
                     est.string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("--f0 (Hz) = 98 is out of range"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(est));

    r = run_cli("estimate " + wav + " --case bass-pluck --d 1.14e-3 --modes 120 --band 20 4000 --no-plots -q --out " +
                est.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    for (const char* name : {"partials.csv", "modes.csv", "fit.json", "case.toml", "case-snippet.toml", "model_curves.csv"})
        EXPECT_TRUE(fs::exists(est / name)) << name;
    // The written case reads its mode table back (source column included) and keeps the pluck.
    const Case original = load_case("bass-pluck");
    const Case estimated = load_case((est / "case.toml").string());
    ASSERT_EQ(estimated.mode_count(), 120u);
    for (std::size_t j = 0; j < 30; ++j) {
        EXPECT_NEAR(estimated.modes.frequency_hz[j] / original.modes.frequency_hz[j], 1.0, 1e-4) << "mode " << j + 1;
        EXPECT_NEAR(estimated.modes.sigma_per_s[j] / original.modes.sigma_per_s[j], 1.0, 0.05) << "mode " << j + 1;
    }
    EXPECT_NEAR(estimated.string.length_m, original.string.length_m, 1e-12);
    EXPECT_EQ(estimated.modes.source.front(), ModeSource::measured);
    EXPECT_EQ(estimated.modes.source.back(), ModeSource::model);  // mode 120 (11.8 kHz) lies above --band
}

// The program under `timeout`: a command that would block ends (exit 124) instead of
// hanging the test.
testing::CommandResult run_cli_within(int seconds, const std::string& arguments) {
    return testing::run_shell("timeout -s KILL " + std::to_string(seconds) + " " + FRETBUZZ_CLI + " " + arguments);
}

// A FLAC file of the samples (16-bit), written by libsndfile.
void write_flac(const fs::path& path, const std::vector<double>& x, int rate) {
    SF_INFO info{};
    info.samplerate = rate;
    info.channels = 1;
    info.format = SF_FORMAT_FLAC | SF_FORMAT_PCM_16;
    SNDFILE* file = sf_open(path.c_str(), SFM_WRITE, &info);
    ASSERT_NE(file, nullptr) << sf_strerror(nullptr);
    sf_writef_double(file, x.data(), static_cast<sf_count_t>(x.size()));
    sf_close(file);
}

const std::string kString = " --L 0.65 --mu 6e-3 --d 1.1e-3 --no-plots -q ";

// The file is checked before anything else: a missing recording is named first.
TEST(EstimateCommand, ChecksTheRecordingFirst) {
    ScratchDir dir("estimate-missing");
    const fs::path out = dir.path() / "out";
    const auto r = run_cli("estimate " + (dir.path() / "missing.wav").string() + " --out " + out.string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("missing.wav"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("--L"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(out));
}

// --case gives L, mu and, where the case has it, d; otherwise a steel string's d is assumed.
TEST(EstimateCommand, CaseSufficesWithoutDiameter) {
    ScratchDir dir("estimate-case-d");
    const fs::path wav = dir.path() / "good.wav";
    write_wav(wav, decay(1.0, 16000, 0.5), 16000);
    auto r = run_cli("estimate " + wav.string() + " --case bass-pluck --no-plots --out " + (dir.path() / "a").string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    // bass-pluck gives no d: that of steel of its mu = 6.69e-3 kg/m, sqrt(4 mu / (pi 7850)) = 1.0417 mm.
    EXPECT_NE(r.output.find("d = 1.04168 mm assumed"), std::string::npos) << r.output;
    EXPECT_NE(read_file(dir.path() / "a" / "case-snippet.toml").find("d = 0.001041677515"), std::string::npos);
    r = run_cli("estimate " + wav.string() + " --case sitar --no-plots -q --out " + (dir.path() / "b").string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(read_file(dir.path() / "b" / "case-snippet.toml").find("d = 0.0004\n"), std::string::npos);
    EXPECT_EQ(load_case((dir.path() / "b" / "case.toml").string()).string.length_m, 0.88);
    // A length that does not fit the case (its pluck and pickup lie beyond 0.5 m): refused.
    r = run_cli("estimate " + wav.string() + " --case bass-pluck --L 0.5 --no-plots -q --out " +
                (dir.path() / "c").string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("the case written from --case bass-pluck is not valid"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir.path() / "c"));
}

// Regular files only, refused before they are opened: a FIFO without a writer must not
// block, /dev/zero must not be read forever.
TEST(EstimateCommand, RefusesSpecialFilesWithoutBlocking) {
    ScratchDir dir("estimate-fifo");
    const fs::path fifo = dir.path() / "take.wav";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    for (const fs::path& path : {fifo, fs::path("/dev/zero")}) {
        const fs::path out = dir.path() / "out";
        const auto r = run_cli_within(20, "estimate " + path.string() + kString + "--out " + out.string());
        EXPECT_EQ(r.exit_code, 2) << path << ": " << r.output;
        EXPECT_NE(r.output.find(path.string() + " is not a regular file"), std::string::npos) << r.output;
        EXPECT_FALSE(fs::exists(out));
    }
}

// Headers that claim more frames than the file holds: buffers follow what is decoded. A
// FLAC claiming 2^35 - 1 frames (256 GiB of doubles) and a WAV claiming 2^31 hold 1 s each.
TEST(EstimateCommand, HeaderFrameCountsAreNotTrusted) {
    ScratchDir dir("estimate-headers");
    const std::vector<double> x = decay(1.0, 16000, 0.5);
    const fs::path flac = dir.path() / "claims.flac", wav = dir.path() / "claims.wav";
    write_flac(flac, x, 16000);
    std::string bytes = read_file(flac);
    // STREAMINFO, the first metadata block at byte 8: total samples are its bits 108-143.
    ASSERT_EQ(bytes.substr(0, 4), "fLaC");
    ASSERT_EQ(bytes[4] & 0x7f, 0);
    bytes[21] = static_cast<char>((bytes[21] & 0xf0) | 0x07);
    for (int i = 22; i < 26; ++i) bytes[static_cast<std::size_t>(i)] = static_cast<char>(0xff);
    write_file(flac, bytes);
    write_wav(wav, x, 16000);
    bytes = read_file(wav);
    const std::uint32_t claimed = 0xfffffff0u;  // data bytes: 2^31 frames of 16 bits
    std::memcpy(bytes.data() + 40, &claimed, 4);
    write_file(wav, bytes);
    for (const fs::path& path : {flac, wav}) {
        const fs::path out = dir.path() / ("out-" + path.extension().string().substr(1));
        const auto r = run_cli_within(120, "estimate " + path.string() + kString + "--out " + out.string());
        EXPECT_EQ(r.exit_code, 0) << path << ": " << r.output;
        EXPECT_TRUE(fs::exists(out / "partials.csv")) << path;
    }
}

// The analysed length is capped (30 s), and so is the file's size (256 MiB, a sparse file
// here); both messages say how to cut the file.
TEST(EstimateCommand, LongRecordingsAreRefusedWithTheCap) {
    ScratchDir dir("estimate-long");
    const fs::path wav = dir.path() / "long.wav", huge = dir.path() / "huge.wav";
    write_wav(wav, decay(31.0, 8000, 0.5), 8000);
    auto r = run_cli_within(120, "estimate " + wav.string() + kString + "--out " + (dir.path() / "out").string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(wav.string() + ": longer than 30 s"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("sox " ), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("ffmpeg "), std::string::npos) << r.output;
    write_wav(huge, decay(1.0, 8000, 0.5), 8000);
    fs::resize_file(huge, std::uintmax_t{300} << 20);
    r = run_cli_within(120, "estimate " + huge.string() + kString + "--out " + (dir.path() / "out").string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(huge.string() + ": 300 MiB, more than the 256 MiB read"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("sox "), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir.path() / "out"));
}

// Only WAV, FLAC and AIFF reach libsndfile: a Sun/NeXT .au file (which it would read) is
// refused by name.
TEST(EstimateCommand, OnlyWavFlacAndAiffAreRead) {
    ScratchDir dir("estimate-au");
    const std::vector<double> x = decay(1.0, 16000, 0.5);
    std::string au = ".snd";
    const auto be32 = [&au](std::uint32_t v) {
        for (int shift = 24; shift >= 0; shift -= 8) au.push_back(static_cast<char>((v >> shift) & 0xff));
    };
    be32(24);
    be32(static_cast<std::uint32_t>(2 * x.size()));
    be32(3);  // 16-bit linear PCM
    be32(16000);
    be32(1);
    for (const double v : x) {
        const auto sample = static_cast<std::uint16_t>(static_cast<std::int16_t>(std::lround(32767.0 * v)));
        au.push_back(static_cast<char>(sample >> 8));
        au.push_back(static_cast<char>(sample & 0xff));
    }
    const fs::path path = dir.path() / "take.au";
    write_file(path, au);
    const auto r = run_cli("estimate " + path.string() + kString + "--out " + (dir.path() / "out").string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(path.string() + ": not a WAV, FLAC or AIFF file"), std::string::npos) << r.output;
}

// A chunk that claims to run past the end of the file is refused before libsndfile parses
// it: this 213-byte RF64 file (found by recording_fuzzer) keeps libsndfile 1.2's LIST
// parser busy for minutes.
TEST(EstimateCommand, ChunksPastTheEndOfTheFileAreRefused) {
    const std::string hex =
        "52463634ffffffff57415645647336341c0000005a01000000f0fffffffffffffffe0000f00000000000010000000000"
        "666d74201000000001000100401f5d00401f0004010008004c495354b3abffffffffffffffffffffffffffffffffffff"
        "ffffffffffffffffffffffffffffffffffffffffffffffffffffffffdfffffffffffffffffffffffffffffffffffffff"
        "ffffffffffffffffffffffffffffffffffffffffff74201000000001000100409f8f7d6b5c605855939fa72aa8a2978a"
        "7c6e635b57585e8f83776c635e5c5f66707c88939c";
    std::string bytes;
    for (std::size_t i = 0; i + 1 < hex.size(); i += 2)
        bytes.push_back(static_cast<char>(std::stoi(hex.substr(i, 2), nullptr, 16)));
    ScratchDir dir("estimate-chunks");
    const fs::path path = dir.path() / "damaged.wav";
    write_file(path, bytes);
    const auto r = run_cli_within(20, "estimate " + path.string() + kString + "--out " + (dir.path() / "out").string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(path.string() + ": its 'LIST' chunk at byte 72 claims 4294945715 bytes, past the end"),
              std::string::npos)
        << r.output;
}

// A steady tone is refused as not a free decay (exit 2, nothing written).
TEST(EstimateCommand, SteadyToneIsNotAFreeDecay) {
    ScratchDir dir("estimate-steady");
    std::vector<double> x(32000);
    for (std::size_t n = 0; n < x.size(); ++n)
        x[n] = (n < 160 ? 0.6 : 0.5) * std::sin(2.0 * std::numbers::pi * 98.0 * static_cast<double>(n) / 16000.0);
    const fs::path wav = dir.path() / "sine.wav", out = dir.path() / "out";
    write_wav(wav, x, 16000);
    const auto r = run_cli("estimate " + wav.string() + kString + "--out " + out.string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("not a free decay"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(out));
}

// --polarisations 2: both partials of each doublet in partials.csv, the weaker ones in
// modes_y.csv, and a case whose y modes are them.
TEST(EstimateCommand, WritesBothPolarisationsWhenAsked) {
    ScratchDir dir("estimate-doublets");
    testing::DecaySpec spec;
    spec.modes = 15;
    spec.separation = 2e-3;
    spec.ratio = 0.6;
    spec.seconds = 3.0;
    const fs::path wav = dir.path() / "doublets.wav", out = dir.path() / "out";
    write_wav(wav, scaled(spec, 0.5), static_cast<int>(spec.rate_hz));
    const std::string options = " --case bass-pluck --modes 40 --max-partial 15 --no-plots -q --out " + out.string();
    auto r = run_cli("estimate " + wav.string() + options + " --polarisations 3");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("--polarisations = 3 is out of range: must be 1 or 2"), std::string::npos) << r.output;
    r = run_cli("estimate " + wav.string() + options + " --polarisations 2");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(read_file(out / "partials.csv").find(",reliable,polarisation,frequency_sd_hz,sigma_sd_per_s,merged\n"),
              std::string::npos);
    EXPECT_NE(read_file(out / "case-snippet.toml").find("[polarisation_y]\ntable = \"modes_y.csv\""),
              std::string::npos);
    const Case c = load_case((out / "case.toml").string());
    ASSERT_TRUE(c.two_polarisations());
    const ModeTable y = c.y_modes();
    ASSERT_EQ(y.size(), 40u);
    for (const testing::TruePartial& t : testing::decay_partials(spec)) {
        if (t.mode < 3 || t.mode > 12) continue;
        const ModeTable& table = t.polarisation == 1 ? c.modes : y;
        const auto j = static_cast<std::size_t>(t.mode - 1);
        EXPECT_NEAR(table.frequency_hz[j] / t.frequency_hz, 1.0, 1e-4) << "mode " << t.mode << "/" << t.polarisation;
        EXPECT_NEAR(table.sigma_per_s[j] / t.sigma_per_s, 1.0, 0.15) << "mode " << t.mode << "/" << t.polarisation;
        EXPECT_EQ(table.source[j], ModeSource::measured) << "mode " << t.mode << "/" << t.polarisation;
    }
    // Above the measured modes y follows z (the models).
    EXPECT_EQ(y.frequency_hz[39], c.modes.frequency_hz[39]);
}

// A doublet below the resolution (41.2 Hz, 0.05 % apart, 2 s at 40 dB: mode 3 beats 0.12
// times in the record): one row, merged = 1 and reliable = 0, and the note on the terminal.
TEST(EstimateCommand, MergedDoubletIsFlaggedWithItsNote) {
    ScratchDir dir("estimate-merged");
    testing::DecaySpec spec;
    spec.f0_hz = 41.2;
    spec.modes = 15;
    spec.separation = 5e-4;
    spec.ratio = 0.8;
    spec.seconds = 2.0;
    spec.snr_db = 40.0;
    const fs::path wav = dir.path() / "close.wav", out = dir.path() / "out";
    write_wav(wav, scaled(spec, 0.5), static_cast<int>(spec.rate_hz));
    const auto r = run_cli("estimate " + wav.string() + " --L 0.863 --mu 6.69e-3 --d 1.14e-3 --max-partial 15 --no-plots --out " +
                           out.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("too close to resolve in this record"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("beating envelope's"), std::string::npos) << r.output;
    std::istringstream rows(read_file(out / "partials.csv"));
    std::string row;
    std::vector<std::string> third;
    while (std::getline(rows, row))
        if (row.starts_with("3,")) third.push_back(row);
    ASSERT_EQ(third.size(), 1u) << read_file(out / "partials.csv");
    // ...,reliable,polarisation,frequency_sd_hz,sigma_sd_per_s,merged
    std::vector<std::string> fields;
    std::istringstream columns(third[0]);
    for (std::string field; std::getline(columns, field, ',');) fields.push_back(field);
    ASSERT_EQ(fields.size(), 13u) << third[0];
    EXPECT_EQ(fields[8], "0") << third[0];   // not reliable
    EXPECT_EQ(fields[12], "1") << third[0];  // merged
}

}  // namespace
}  // namespace fretbuzz
