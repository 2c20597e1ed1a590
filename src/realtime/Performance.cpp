#include "fretbuzz/realtime/Performance.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "fretbuzz/Error.hpp"

namespace fretbuzz {

int open_string_note(const Case& c) {
    return static_cast<int>(std::lround(69.0 + 12.0 * std::log2(c.modes.frequency_hz.front() / 440.0)));
}

long rendered_samples(const Score& score, double host_rate_hz) {
    const double samples = std::round((score.end_s() + score.tail_s) * host_rate_hz);
    if (!(samples <= static_cast<double>(kMaxRenderedSamples))) {
        std::ostringstream what;
        what << "the performance (" << score.end_s() + score.tail_s << " s with its tail) at " << host_rate_hz
             << " Hz is " << std::fixed << std::setprecision(0) << samples << " samples; at most " << kMaxRenderedSamples
             << " are rendered (an hour at 48 kHz): lower --rate or shorten it";
        throw InputError(what.str());
    }
    return static_cast<long>(samples);
}

RenderedPerformance render_performance(const Case& open, const Score& p, const EngineOptions& options,
                                       std::size_t block) {
    const auto start = std::chrono::steady_clock::now();
    const double rate = options.host_rate_hz;
    const long total = rendered_samples(p, rate);  // checked before the engine or the audio is allocated
    // One voice: the string, its finger moved from note to note.
    EngineOptions o = options;
    if (p.pickup > 0.0) o.pickup_m = p.pickup * open.string.length_m;
    Engine voice(open, o);
    for (const ScoreNote& n : p.notes)
        if (n.fret > voice.fret_count())
            throw InputError(out_of_range_message("note at t = " + std::to_string(n.time_s) + " s: fret", n.fret,
                                                  "0 (the open string) to " + std::to_string(voice.fret_count()) +
                                                      ", the frets of " + open.name));
    struct Event {
        long sample;
        bool on;
        const ScoreNote* note;
    };
    std::vector<Event> events;
    for (const ScoreNote& n : p.notes) {
        events.push_back({std::lround(n.time_s * rate), true, &n});
        events.push_back({std::lround((n.time_s + n.duration_s) * rate), false, &n});
    }
    // At equal times a note-off goes first, so a repeated note is struck after the mute lifts.
    std::stable_sort(events.begin(), events.end(),
                     [](const Event& a, const Event& b) { return a.sample < b.sample || (a.sample == b.sample && !a.on && b.on); });
    RenderedPerformance out;
    out.audio.assign(static_cast<std::size_t>(total), 0.0);
    std::vector<float> buffer(block);
    const ScoreNote* sounding = nullptr;  // the note the string plays now (the last struck)
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
