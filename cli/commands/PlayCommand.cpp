// `fretbuzz play CASE --notes FILE.toml|--midi FILE.mid --out out.wav`: a performance rendered
// offline through the real-time engine, block by block as a plugin host would.
#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>

#include "../Commands.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/MidiFile.hpp"
#include "fretbuzz/input/Score.hpp"
#include "fretbuzz/output/AtomicFile.hpp"
#include "fretbuzz/output/AudioWriter.hpp"
#include "fretbuzz/realtime/Performance.hpp"

namespace fretbuzz::cli {

namespace {

// The formats the audio writer writes, named by the extension (any case).
constexpr std::array<const char*, 3> kAudioExtensions = {".wav", ".flac", ".ogg"};

struct PlayArguments {
    std::string case_name;
    std::string notes;
    std::string midi;
    std::string out;
    double rate = 48000.0;
    int oversampling = 0;
    int max_oversampling = 8;
    int bits = 24;
    int open_note = -1;
    std::size_t block = 256;
};

void check_extension(const std::filesystem::path& out) {
    std::string extension = out.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (std::find(kAudioExtensions.begin(), kAudioExtensions.end(), extension) != kAudioExtensions.end()) return;
    throw InputError("--out " + out.string() + ": the extension names the format: .wav (PCM, --bits), .flac (FLAC, --bits) or .ogg (Ogg Vorbis)");
}

int play(const PlayArguments& a) {
    if (a.notes.empty() == a.midi.empty()) throw InputError("play: give exactly one of --notes FILE.toml or --midi FILE.mid");
    if (a.bits != 16 && a.bits != 24) throw InputError(out_of_range_message("--bits", a.bits, "16 or 24"));
    if (a.block < 1 || a.block > 4096) throw InputError(out_of_range_message("--block", static_cast<double>(a.block), "1 to 4096"));
    if (a.open_note > 127) throw InputError(out_of_range_message("--open-note", a.open_note, "0 to 127"));
    // Everything about --out is checked before the work: the take is written beside it and
    // renamed into place only once whole.
    check_extension(a.out);
    AtomicFile out(a.out, "--out");
    const Case c = load_case(a.case_name);
    const int open_note = a.open_note >= 0 ? a.open_note : open_string_note(c);
    const int frets = std::min(kMaxFret, static_cast<int>(c.fret_positions_m.size()));
    const Score p = a.notes.empty() ? load_midi(a.midi, open_note, frets) : load_note_list(a.notes);
    for (const std::string& w : p.warnings) std::fprintf(stderr, "fretbuzz: warning: %s\n", w.c_str());
    EngineOptions options;
    options.host_rate_hz = a.rate;
    options.oversampling = a.oversampling;
    options.max_oversampling = a.max_oversampling;
    RenderedPerformance r = render_performance(c, p, options, a.block);
    const double seconds = static_cast<double>(r.audio.size()) / a.rate;
    const RenderedPerformance::Voice& v = r.voice;
    std::printf("%s: %zu modes at %d x %.0f Hz, %d frets, latency %.1f samples (%.3f ms, the decimation filter's delay)\n"
                "  oversampling %d: %s\n",
                c.name.c_str(), v.modes, v.oversampling, a.rate, v.frets, v.latency_samples, 1e3 * v.latency_samples / a.rate,
                v.oversampling, v.rate_choice);
    if (v.resets > 0) std::fprintf(stderr, "fretbuzz: warning: the energy guard silenced the string %ld times\n", v.resets);
    if (v.clamped > 0) std::fprintf(stderr, "fretbuzz: warning: %ld values clamped into range\n", v.clamped);
    write_normalised_audio(out.temporary(), r.audio, a.rate, a.bits);
    out.commit();
    std::printf("%s: %.2f s of audio, %zu notes, rendered in %.2f s (%.1f x real time)\n", a.out.c_str(), seconds,
                p.notes.size(), r.wall_seconds, seconds / r.wall_seconds);
    return 0;
}

}  // namespace

void add_play_command(CLI::App& app, Action& action) {
    auto a = std::make_shared<PlayArguments>();
    CLI::App* cmd = app.add_subcommand("play", "Render a note list or MIDI file through the real-time engine");
    cmd->add_option("case", a->case_name, "Built-in case name or path to a .toml file")->required();
    cmd->add_option("--notes", a->notes, "Note list (TOML: [[note]] time, fret, duration, velocity, position)");
    cmd->add_option("--midi", a->midi, "Standard MIDI file: note - open-string note = fret");
    cmd->add_option("--out", a->out, "Output audio file: .wav, .flac or .ogg (Ogg Vorbis); written whole or not at all")->required();
    cmd->add_option("--rate", a->rate, "Host sampling rate, Hz (default 48000)");
    cmd->add_option("--oversampling", a->oversampling, "Internal rate / host rate (default: chosen from the modes)");
    cmd->add_option("--max-oversampling", a->max_oversampling, "Largest automatic oversampling (default 8)");
    cmd->add_option("--bits", a->bits, "WAV or FLAC sample size, 16 or 24 (default 24)");
    cmd->add_option("--open-note", a->open_note, "MIDI note of the open string (default: nearest its first mode)");
    cmd->add_option("--block", a->block, "Block size in samples, 1 to 4096 (default 256)");
    cmd->callback([a, &action] { action = [a] { return play(*a); }; });
}

}  // namespace fretbuzz::cli
