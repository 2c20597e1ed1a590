// The fretbuzz LV2 instruments: thin shells over the real-time engines.
//
// One string of a preset (bass, guitar, sitar, tanpura), over Engine: MIDI note n plays fret
// n - (the open string's note), velocity sets the pluck strength, note-off mutes. Each fret is
// a voice prepared at instantiation (the string stopped at that fret: a stand-in for a
// modelled finger).
//
// Strings on one bridge (sitar-taraf: the sitar's main string and its 13 taraf strings;
// guitar-chord: six strings), over BridgeEngine, one voice of every string: a note is played on
// the highest string whose open note is at most the note and whose frets reach it (the sitar's
// strings have none: each string is the key of its own open note), the finger put down behind
// the fret first; note-off lifts that finger and mutes the string, as the one-string voices'
// note-off does (the other strings ring on, the taraf with what the bridge gave them). Its one
// control is the pluck position.
//
// The work of a block is bounded whatever the host sends: at most kVoices voices sound at once
// (a note beyond them takes the voice released longest ago, or else the one held longest,
// which fades out over kFadeFrames), and at most kVoices notes start in one block: of a burst
// of note-ons only the block's last kVoices start, since the earlier ones would have been
// taken for the later ones within the block anyway. run() allocates nothing and takes no lock.
#include <lv2/atom/atom.h>
#include <lv2/atom/util.h>
#include <lv2/core/lv2.h>
#include <lv2/log/log.h>
#include <lv2/log/logger.h>
#include <lv2/midi/midi.h>
#include <lv2/urid/urid.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <exception>
#include <memory>
#include <string>
#include <vector>

#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/StoppedString.hpp"
#include "fretbuzz/input/StringsCaseFile.hpp"
#include "fretbuzz/realtime/BridgeEngine.hpp"
#include "fretbuzz/realtime/Engine.hpp"
#include "fretbuzz/realtime/Performance.hpp"
#include "fretbuzz/realtime/VoiceAllocation.hpp"

namespace {

using namespace fretbuzz;

constexpr int kVoices = 6;  // sounding at once, and started in one block
constexpr int kFrets = kMaxFret + 1;
constexpr std::size_t kChunk = 4096;
constexpr uint32_t kFadeFrames = 64;  // a voice taken for another note fades out over 1.3 ms at 48 kHz
constexpr double kFullStrength = 1.5;  // m/s at MIDI velocity 127

enum Port : uint32_t { kMidiIn, kOut, kPluck, kPickup, kBuzz, kDamping, kPortCount };
// An output control after the inputs: the latency the host compensates (lv2:latency).
constexpr uint32_t kLatencyPort = kPortCount;

struct Control {
    const char* name;
    float low, high;
};
// The ranges the .ttl declares: values outside are clamped, with a warning.
constexpr std::array<Control, kPortCount> kControls = {
    {{"", 0, 0}, {"", 0, 0}, {"pluck", 0.02f, 0.98f}, {"pickup", 0.02f, 0.98f}, {"buzz", -2.0f, 0.5f}, {"damping", 0.1f, 10.0f}}};

// A control's value within its range; a warning when a new raw value is out of it.
float clamped(float raw, const Control& c, float& last, LV2_Log_Logger& logger) {
    const float value = std::isnan(raw) ? c.low : std::clamp(raw, c.low, c.high);
    if (raw != last && !(std::isnan(raw) && std::isnan(last)) && value != raw)
        lv2_log_warning(&logger, "fretbuzz: %s = %g is out of range [%g, %g]; using %g\n", c.name, static_cast<double>(raw),
                        static_cast<double>(c.low), static_cast<double>(c.high), static_cast<double>(value));
    last = raw;
    return value;
}

bool is_note_on(const uint8_t* msg) { return lv2_midi_message_type(msg) == LV2_MIDI_MSG_NOTE_ON && msg[2] > 0; }
bool is_note_off(const uint8_t* msg) {
    const uint8_t status = lv2_midi_message_type(msg);
    return !is_note_on(msg) && (status == LV2_MIDI_MSG_NOTE_OFF || status == LV2_MIDI_MSG_NOTE_ON);
}

// One block: render(from, to) between the MIDI events that act, event(msg) at each. Of a burst
// of note-ons that act (plays(msg)) only the block's last `most` start: the earlier ones would
// have been taken over within the block anyway. acts(msg) says whether an event does anything.
template <class Plays, class Acts, class Render, class Event>
void play_block(const LV2_Atom_Sequence* midi, LV2_URID midi_event, uint32_t frames, long most, Plays&& plays,
                Acts&& acts, Render&& render, Event&& event) {
    long note_ons = 0;
    LV2_ATOM_SEQUENCE_FOREACH(midi, ev) {
        const auto* msg = reinterpret_cast<const uint8_t*>(ev + 1);
        if (ev->body.type == midi_event && ev->body.size >= 3 && is_note_on(msg) && plays(msg)) ++note_ons;
    }
    long skip = std::max(0L, note_ons - most);
    uint32_t done = 0;
    LV2_ATOM_SEQUENCE_FOREACH(midi, ev) {
        if (ev->body.type != midi_event || ev->body.size < 3) continue;
        const auto* msg = reinterpret_cast<const uint8_t*>(ev + 1);
        if (!plays(msg)) continue;
        if (is_note_on(msg) && skip > 0) {
            --skip;
            continue;
        }
        if (!acts(msg)) continue;
        const auto at = static_cast<uint32_t>(std::clamp<int64_t>(ev->time.frames, done, frames));
        render(done, at);
        done = at;
        event(msg);
    }
    render(done, frames);
}

struct Preset {
    const char* uri;
    const char* case_name;
};
constexpr std::array<Preset, 4> kPresets = {{{"urn:fretbuzz:bass", "bass-pluck"},
                                             {"urn:fretbuzz:guitar", "guitar-point"},
                                             {"urn:fretbuzz:sitar", "sitar"},
                                             {"urn:fretbuzz:tanpura", "tanpura"}}};

struct Voice {
    std::unique_ptr<Engine> engine;
    std::array<float, kPortCount> applied{};  // control values this voice last took
    long started = -1;                        // note-on order; -1: not held
    long released = -1;                       // note-off order, while it rings out
    bool active = false;                      // sounding (held, ringing out or fading)
    uint32_t fading = 0;                      // frames left of its fade-out; 0: none
};

struct Instrument {
    std::array<Voice, kFrets> voices;
    int open_note = 40;
    long events = 0;  // note-ons and -offs so far: the order voices are taken in
    std::array<const float*, kPortCount> controls{};
    const LV2_Atom_Sequence* midi = nullptr;
    float* out = nullptr;
    float* latency = nullptr;      // the latency port, if the host connected it
    float latency_samples = 0.0f;  // the voices' decimation delay (the same for all)
    std::array<float, kPortCount> last{};  // raw values last seen, to warn once per change
    std::array<float, kChunk> scratch{};
    LV2_URID midi_event = 0;
    LV2_Log_Logger logger{};

    float control(uint32_t port) { return clamped(*controls[port], kControls[port], last[port], logger); }

    void sync(Voice& v, const std::array<float, kPortCount>& now) {
        Engine& e = *v.engine;
        if (now[kPickup] != v.applied[kPickup]) e.set_pickup(now[kPickup] * e.length_m());
        if (now[kBuzz] != v.applied[kBuzz]) e.set_obstacle_offset(now[kBuzz] * 1e-3);
        if (now[kDamping] != v.applied[kDamping]) e.set_damping_scale(now[kDamping]);
        v.applied = now;
    }

    // The MIDI note's voice, or nullptr for a note outside the frets.
    Voice* voice_of(const uint8_t* msg) {
        const int fret = msg[1] - open_note;
        return fret >= 0 && fret < kFrets ? &voices[static_cast<std::size_t>(fret)] : nullptr;
    }

    // Room for `v` to sound: beyond kVoices, the voice the real-time layer's rule picks fades out.
    void make_room(const Voice& v) {
        const auto turn = [](const Voice& o) { return VoiceTurn{o.active, o.fading > 0, o.started, o.released}; };
        if (const auto k = voice_giving_way(voices, static_cast<std::size_t>(&v - voices.data()), kVoices, turn)) {
            Voice& taken = voices[*k];
            taken.fading = kFadeFrames;
            taken.started = taken.released = -1;
        }
    }

    void note_on(Voice& v, int velocity, const std::array<float, kPortCount>& now) {
        if (v.fading > 0) stop(v);  // taken for another note in this block: it starts afresh
        make_room(v);
        sync(v, now);
        v.engine->mute(false);
        v.engine->strike({now[kPluck] * v.engine->length_m(), kFullStrength * velocity / 127.0, 0.01, false});
        v.started = events++;
        v.released = -1;
        v.active = true;
    }

    void note_off(Voice& v) {
        v.engine->mute(true);
        v.started = -1;
        v.released = events++;
    }

    static void stop(Voice& v) {
        v.engine->stop();
        v.active = false;
        v.fading = 0;
        v.started = v.released = -1;
    }

    void render(uint32_t from, uint32_t to) {
        while (from < to) {
            const uint32_t n = std::min<uint32_t>(to - from, kChunk);
            for (Voice& v : voices) {
                if (!v.active) continue;
                const uint32_t frames = v.fading > 0 ? std::min(n, v.fading) : n;
                const std::span<float> chunk(scratch.data(), frames);
                v.engine->process(chunk);
                for (uint32_t i = 0; i < frames; ++i) {
                    const float gain = v.fading > 0 ? static_cast<float>(v.fading - i) / kFadeFrames : 1.0f;
                    out[from + i] += gain * chunk[i];
                }
                if (v.fading > 0) {
                    v.fading -= frames;
                    if (v.fading == 0) stop(v);
                } else if (v.started < 0 && !v.engine->sounding()) {
                    v.active = false;
                    v.released = -1;
                }
            }
            from += n;
        }
    }

    void run(uint32_t frames) {
        if (latency != nullptr) *latency = latency_samples;
        std::fill(out, out + frames, 0.0f);
        std::array<float, kPortCount> now{};
        for (uint32_t p = kPluck; p < kPortCount; ++p) now[p] = control(p);
        for (Voice& v : voices)
            if (v.active && v.fading == 0) sync(v, now);
        // Only the block's last kVoices note-ons start (see the top of this file).
        play_block(
            midi, midi_event, frames, kVoices, [this](const uint8_t* msg) { return voice_of(msg) != nullptr; },
            [this](const uint8_t* msg) { return is_note_on(msg) || (is_note_off(msg) && voice_of(msg)->started >= 0); },
            [this](uint32_t from, uint32_t to) { render(from, to); },
            [&](const uint8_t* msg) {
                if (is_note_on(msg))
                    note_on(*voice_of(msg), msg[2], now);
                else
                    note_off(*voice_of(msg));
            });
    }
};

// What the plugins need from the host: the URID map (required: MIDI events are told apart by
// their URID) and, if given, its log.
struct HostFeatures {
    LV2_URID_Map* map = nullptr;
    LV2_Log_Log* log = nullptr;
    explicit HostFeatures(const LV2_Feature* const* features) {
        for (int i = 0; features != nullptr && features[i] != nullptr; ++i) {
            if (std::strcmp(features[i]->URI, LV2_URID__map) == 0) map = static_cast<LV2_URID_Map*>(features[i]->data);
            if (std::strcmp(features[i]->URI, LV2_LOG__log) == 0) log = static_cast<LV2_Log_Log*>(features[i]->data);
        }
    }
};

LV2_Handle instantiate(const LV2_Descriptor* descriptor, double rate, const char*, const LV2_Feature* const* features) {
    const HostFeatures host(features);
    LV2_URID_Map* map = host.map;
    LV2_Log_Log* log = host.log;
    if (map == nullptr) return nullptr;  // required: MIDI events are told apart by their URID
    auto instrument = std::make_unique<Instrument>();
    lv2_log_logger_init(&instrument->logger, map, log);
    instrument->midi_event = map->map(map->handle, LV2_MIDI__MidiEvent);
    try {
        const Preset* preset = nullptr;
        for (const Preset& p : kPresets)
            if (std::strcmp(p.uri, descriptor->URI) == 0) preset = &p;
        if (preset == nullptr) return nullptr;
        const Case open = load_case(preset->case_name);
        instrument->open_note = open_string_note(open);
        EngineOptions options;
        options.host_rate_hz = rate;
        options.gain_per_m = 300.0;
        // At most 4x oversampling: six voices must keep up with the host on one core (the six
        // guitar voices of bench/bench_realtime.cpp; docs/performance.md, real time).
        options.max_oversampling = 4;
        for (int k = 0; k < kFrets; ++k) {
            const Case c = k == 0 ? open : stopped_string(open, fret_stop_m(open, k), open.mode_count());
            Voice& v = instrument->voices[static_cast<std::size_t>(k)];
            v.engine = std::make_unique<Engine>(c, options);
            v.applied = {0, 0, -1, -1, 0, 1};  // the engine's own pickup; buzz 0; damping 1
        }
        // Whole frames, as hosts compensate them (the filter's delay is (length - 1) / 2M).
        instrument->latency_samples = static_cast<float>(std::round(instrument->voices[0].engine->latency_samples()));
    } catch (const std::exception& e) {
        lv2_log_error(&instrument->logger, "fretbuzz: cannot prepare %s: %s\n", descriptor->URI, e.what());
        return nullptr;
    }
    instrument->last = {0.0f, 0.0f, 0.8f, 0.9f, 0.0f, 1.0f};  // the .ttl defaults
    return instrument.release();
}

// Ports 0 and 1, the same in every plugin: MIDI in, audio out. False for any other.
template <class Plugin>
bool connect_midi_and_out(Plugin& self, uint32_t port, void* data) {
    if (port == kMidiIn) self.midi = static_cast<const LV2_Atom_Sequence*>(data);
    if (port == kOut) self.out = static_cast<float*>(data);
    return port == kMidiIn || port == kOut;
}

void connect_port(LV2_Handle handle, uint32_t port, void* data) {
    auto* self = static_cast<Instrument*>(handle);
    if (connect_midi_and_out(*self, port, data)) return;
    if (port < kPortCount)
        self->controls[port] = static_cast<const float*>(data);
    else if (port == kLatencyPort)
        self->latency = static_cast<float*>(data);
}

void run(LV2_Handle handle, uint32_t frames) { static_cast<Instrument*>(handle)->run(frames); }

void cleanup(LV2_Handle handle) { delete static_cast<Instrument*>(handle); }

// Strings on one bridge, one BridgeEngine (see the top of this file).
enum StringsPort : uint32_t { kStringsPluck = 2, kStringsLatency };  // after MIDI in and out
constexpr Control kStringsPluckControl = {"pluck", 0.02f, 0.98f};
constexpr std::array<Preset, 2> kStringsPresets = {{{"urn:fretbuzz:sitar-taraf", "sitar-taraf"},
                                                    {"urn:fretbuzz:guitar-chord", "guitar-chord"}}};

struct Strings {
    std::unique_ptr<BridgeEngine> engine;
    std::vector<int> open_note;    // per string
    std::vector<int> fret_counts;  // per string (the engine's)
    std::vector<int> playing;    // per string: the note it plays (-1: none)
    const LV2_Atom_Sequence* midi = nullptr;
    float* out = nullptr;
    const float* pluck = nullptr;
    float* latency = nullptr;
    float latency_samples = 0.0f;
    float last_pluck = 0.8f;  // the .ttl default
    LV2_URID midi_event = 0;
    LV2_Log_Logger logger{};

    // The string that plays `note` (the real-time layer's rule); -1 if none.
    int string_of(int note) const { return string_for_note(open_note, fret_counts, note); }

    void note_on(int note, int velocity, float where) {
        const auto s = static_cast<std::size_t>(string_of(note));
        const int fret = note - open_note[s];
        engine->mute(s, false);
        if (engine->fret_count(s) > 0) engine->finger_down(s, fret);  // 0 lifts it
        const double stop = engine->fret_position_m(s, fret);
        engine->strike(s, {stop + where * (engine->length_m(s) - stop), kFullStrength * velocity / 127.0, 0.01, false});
        playing[s] = note;
    }

    void note_off(int note) {
        const auto s = static_cast<std::size_t>(string_of(note));
        if (playing[s] != note) return;
        engine->finger_up(s);
        engine->mute(s, true);
        playing[s] = -1;
    }

    void run(uint32_t frames) {
        if (latency != nullptr) *latency = latency_samples;
        const float where = clamped(*pluck, kStringsPluckControl, last_pluck, logger);
        // At most one note-on per string starts in a block.
        play_block(
            midi, midi_event, frames, static_cast<long>(open_note.size()), [this](const uint8_t* msg) { return string_of(msg[1]) >= 0; },
            [](const uint8_t*) { return true; },
            [this](uint32_t from, uint32_t to) { engine->process(std::span<float>(out + from, to - from)); },
            [&](const uint8_t* msg) {
                if (is_note_on(msg))
                    note_on(msg[1], msg[2], where);
                else if (is_note_off(msg))
                    note_off(msg[1]);
            });
    }
};

LV2_Handle instantiate_strings(const LV2_Descriptor* descriptor, double rate, const char*,
                               const LV2_Feature* const* features) {
    const HostFeatures host(features);
    if (host.map == nullptr) return nullptr;
    auto strings = std::make_unique<Strings>();
    lv2_log_logger_init(&strings->logger, host.map, host.log);
    strings->midi_event = host.map->map(host.map->handle, LV2_MIDI__MidiEvent);
    try {
        const Preset* preset = nullptr;
        for (const Preset& p : kStringsPresets)
            if (std::strcmp(p.uri, descriptor->URI) == 0) preset = &p;
        if (preset == nullptr) return nullptr;
        const StringsCase sc = parse_strings_case(*read_strings_case_text(preset->case_name));
        BridgeEngineOptions options;
        options.engine.host_rate_hz = rate;
        options.engine.gain_per_m = 300.0;
        // At most 4x oversampling, as the one-string plugin (docs/performance.md, real time).
        options.engine.max_oversampling = 4;
        strings->engine = std::make_unique<BridgeEngine>(sc, options);
        for (const Case& c : sc.strings) strings->open_note.push_back(open_string_note(c));
        for (std::size_t s = 0; s < sc.strings.size(); ++s) strings->fret_counts.push_back(strings->engine->fret_count(s));
        strings->playing.assign(sc.strings.size(), -1);
        strings->latency_samples = static_cast<float>(std::round(strings->engine->latency_samples()));
    } catch (const std::exception& e) {
        lv2_log_error(&strings->logger, "fretbuzz: cannot prepare %s: %s\n", descriptor->URI, e.what());
        return nullptr;
    }
    return strings.release();
}

void connect_strings(LV2_Handle handle, uint32_t port, void* data) {
    auto* self = static_cast<Strings*>(handle);
    if (connect_midi_and_out(*self, port, data)) return;
    if (port == kStringsPluck) self->pluck = static_cast<const float*>(data);
    if (port == kStringsLatency) self->latency = static_cast<float*>(data);
}

void run_strings(LV2_Handle handle, uint32_t frames) { static_cast<Strings*>(handle)->run(frames); }

void cleanup_strings(LV2_Handle handle) { delete static_cast<Strings*>(handle); }

const void* extension_data(const char*) { return nullptr; }

constexpr LV2_Descriptor descriptor(const char* uri) {
    return {uri, instantiate, connect_port, nullptr, run, nullptr, cleanup, extension_data};
}
constexpr LV2_Descriptor strings_descriptor(const char* uri) {
    return {uri, instantiate_strings, connect_strings, nullptr, run_strings, nullptr, cleanup_strings, extension_data};
}
const std::array<LV2_Descriptor, kPresets.size() + kStringsPresets.size()> kDescriptors = {
    descriptor(kPresets[0].uri),        descriptor(kPresets[1].uri),
    descriptor(kPresets[2].uri),        descriptor(kPresets[3].uri),
    strings_descriptor(kStringsPresets[0].uri), strings_descriptor(kStringsPresets[1].uri)};

}  // namespace

LV2_SYMBOL_EXPORT const LV2_Descriptor* lv2_descriptor(uint32_t index) {
    return index < kDescriptors.size() ? &kDescriptors[index] : nullptr;
}
