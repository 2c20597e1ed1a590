#include "fretbuzz/realtime/Performance.hpp"

#include <smf.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>

#include "../input/TomlSection.hpp"
#include "fretbuzz/Error.hpp"

namespace fretbuzz {

namespace {
double in_range(TomlSection& s, std::string_view key, double fallback, double low, double high, const char* range) {
    const double v = s.number_or(key, fallback);
    if (!(v >= low && v <= high)) throw InputError(out_of_range_message(s.key_path(key), v, range));
    return v;
}
}  // namespace

Performance parse_note_list(std::string_view toml_text, const std::string& source_name) {
    const toml::table root = parse_toml_document(toml_text, source_name);
    TomlSection top(root, "");
    Performance p;
    if (auto play = top.optional_section("play")) {
        p.tail_s = in_range(*play, "tail", p.tail_s, 0.0, 600.0, "[0, 600] s");
        p.strength_m_per_s = in_range(*play, "strength", p.strength_m_per_s, 0.0, 20.0, "[0, 20] m/s");
        p.width_m = in_range(*play, "width", p.width_m, 1e-4, 0.5, "[1e-4, 0.5] m");
        if (play->has("pickup")) p.pickup = in_range(*play, "pickup", 0.5, 0.0, 1.0, "(0, 1)");
        if (p.pickup == 0.0 || p.pickup == 1.0)
            throw InputError(out_of_range_message("play.pickup", p.pickup, "(0, 1)"));
        play->finish();
    }
    for (TomlSection& n : top.sections("note")) {
        PlayedNote note;
        note.time_s = in_range(n, "time", 0.0, 0.0, 3600.0, "[0, 3600] s");
        note.duration_s = in_range(n, "duration", note.duration_s, 0.0, 600.0, "[0, 600] s");
        note.fret = static_cast<int>(n.optional_count("fret", 0, kMaxFret).value_or(0));
        note.velocity = in_range(n, "velocity", note.velocity, 0.0, 1.0, "[0, 1]");
        note.position = in_range(n, "position", note.position, 0.01, 0.99, "[0.01, 0.99]");
        n.finish();
        p.notes.push_back(note);
    }
    top.finish();
    if (p.notes.empty()) throw InputError(source_name + ": note: at least one [[note]] is required");
    return p;
}

Performance load_note_list(const std::filesystem::path& path) {
    std::ifstream in(path);
    if (!in) throw InputError("--notes: cannot read " + path.string());
    std::stringstream text;
    text << in.rdbuf();
    return parse_note_list(text.str(), path.string());
}

int open_string_note(const Case& c) {
    return static_cast<int>(std::lround(69.0 + 12.0 * std::log2(c.modes.frequency_hz.front() / 440.0)));
}

Performance load_midi(const std::filesystem::path& path, int open_note, int max_fret) {
    smf_t* smf = smf_load(path.c_str());
    if (smf == nullptr) throw InputError("--midi: " + path.string() + " is not a readable standard MIDI file");
    Performance p;
    std::map<int, std::pair<double, double>> sounding;  // key -> (start, velocity)
    long skipped = 0;
    smf_event_t* event = nullptr;
    while ((event = smf_get_next_event(smf)) != nullptr) {
        if (smf_event_is_metadata(event) || event->midi_buffer_length < 3) continue;
        const int status = event->midi_buffer[0] & 0xF0;
        const int key = event->midi_buffer[1] | ((event->midi_buffer[0] & 0x0F) << 8);  // note and channel
        const int velocity = event->midi_buffer[2];
        const bool on = status == 0x90 && velocity > 0;
        const bool off = status == 0x80 || (status == 0x90 && velocity == 0);
        if (on) {
            sounding[key] = {event->time_seconds, velocity / 127.0};
        } else if (off) {
            const auto it = sounding.find(key);
            if (it == sounding.end()) continue;
            const int fret = (key & 0x7F) - open_note;
            if (fret < 0 || fret > max_fret) {
                ++skipped;
            } else {
                PlayedNote note;
                note.time_s = it->second.first;
                note.duration_s = event->time_seconds - it->second.first;
                note.fret = fret;
                note.velocity = it->second.second;
                p.notes.push_back(note);
            }
            sounding.erase(it);
        }
    }
    smf_delete(smf);
    if (skipped > 0)
        p.warnings.push_back(std::to_string(skipped) + " MIDI notes outside the string's range (MIDI " +
                             std::to_string(open_note) + " to " + std::to_string(open_note + max_fret) + ") skipped");
    if (p.notes.empty()) throw InputError("--midi: " + path.string() + " holds no note the string can play");
    std::sort(p.notes.begin(), p.notes.end(), [](const auto& a, const auto& b) { return a.time_s < b.time_s; });
    return p;
}

RenderedPerformance render_performance(const Case& open, const Performance& p, const EngineOptions& options,
                                       std::size_t block) {
    const auto start = std::chrono::steady_clock::now();
    const double rate = options.host_rate_hz;
    // One voice: the string, its finger moved from note to note.
    EngineOptions o = options;
    if (p.pickup > 0.0) o.pickup_m = p.pickup * open.string.length_m;
    Engine voice(open, o);
    for (const PlayedNote& n : p.notes)
        if (n.fret > voice.fret_count())
            throw InputError(out_of_range_message("note at t = " + std::to_string(n.time_s) + " s: fret", n.fret,
                                                  "0 (the open string) to " + std::to_string(voice.fret_count()) +
                                                      ", the frets of " + open.name));
    struct Event {
        long sample;
        bool on;
        const PlayedNote* note;
    };
    std::vector<Event> events;
    double end_s = 0.0;
    for (const PlayedNote& n : p.notes) {
        events.push_back({std::lround(n.time_s * rate), true, &n});
        events.push_back({std::lround((n.time_s + n.duration_s) * rate), false, &n});
        end_s = std::max(end_s, n.time_s + n.duration_s);
    }
    // At equal times a note-off goes first, so a repeated note is struck after the mute lifts.
    std::stable_sort(events.begin(), events.end(),
                     [](const Event& a, const Event& b) { return a.sample < b.sample || (a.sample == b.sample && !a.on && b.on); });
    const long total = std::lround((end_s + p.tail_s) * rate);
    RenderedPerformance out;
    out.audio.assign(static_cast<std::size_t>(total), 0.0);
    std::vector<float> buffer(block);
    const PlayedNote* sounding = nullptr;  // the note the string plays now (the last struck)
    long now = 0;
    std::size_t next = 0;
    while (now < total) {
        while (next < events.size() && events[next].sample <= now) {
            const Event& e = events[next++];
            if (e.on) {
                // One string: a new note moves the finger (or lifts it for the open string) and plucks.
                sounding = e.note;
                voice.mute(false);
                voice.finger_down(e.note->fret);
                const double stop = voice.fret_position_m(e.note->fret);
                voice.strike({stop + e.note->position * (voice.length_m() - stop),
                              e.note->velocity * p.strength_m_per_s, p.width_m, false});
            } else if (e.note == sounding) {
                voice.mute(true);
                voice.finger_up();
                sounding = nullptr;
            }
        }
        const long until = next < events.size() ? std::min(total, events[next].sample) : total;
        const auto size = static_cast<std::size_t>(std::min<long>(until - now, static_cast<long>(block)));
        if (size == 0) continue;
        const std::span<float> view(buffer.data(), size);
        voice.process(view);
        for (std::size_t i = 0; i < size; ++i) out.audio[static_cast<std::size_t>(now) + i] = view[i];
        now += static_cast<long>(size);
    }
    out.voice = {voice.fret_count(), voice.oversampling(), voice.mode_count(), voice.health().resets,
                 voice.health().clamped, voice.latency_samples(), voice.rate_choice()};
    out.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return out;
}

}  // namespace fretbuzz
