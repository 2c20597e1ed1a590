// The fretbuzz LV2 instrument: a thin shell over the real-time Engine. One string of a preset
// (bass, guitar, sitar, tanpura), so one note at a time, as on a real string: MIDI note n puts
// the engine's finger down behind fret n - (the open string's note) (the open note lifts it)
// and plucks; velocity sets the pluck strength; the note-off of the note sounding mutes the
// string and lifts the finger. Notes beyond the preset's frets are ignored (the sitar and the
// tanpura presets have a bridge and no frets: they play their open string). run() allocates
// nothing and takes no lock.
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

#include "fretbuzz/io/CaseFile.hpp"
#include "fretbuzz/realtime/Engine.hpp"
#include "fretbuzz/realtime/Performance.hpp"

namespace {

using namespace fretbuzz;

constexpr std::size_t kChunk = 4096;
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

struct Preset {
    const char* uri;
    const char* case_name;
};
constexpr std::array<Preset, 4> kPresets = {{{"urn:fretbuzz:bass", "bass-pluck"},
                                             {"urn:fretbuzz:guitar", "guitar-neck"},
                                             {"urn:fretbuzz:sitar", "sitar"},
                                             {"urn:fretbuzz:tanpura", "tanpura"}}};

struct Instrument {
    std::unique_ptr<Engine> engine;           // the string
    std::array<float, kPortCount> applied{};  // control values the engine last took
    int held = -1;                            // the MIDI note sounding; -1: none held
    bool active = false;                      // sounding (held or ringing out)
    int open_note = 40;
    std::array<const float*, kPortCount> controls{};
    const LV2_Atom_Sequence* midi = nullptr;
    float* out = nullptr;
    float* latency = nullptr;      // the latency port, if the host connected it
    float latency_samples = 0.0f;  // the engine's decimation delay
    std::array<float, kPortCount> last{};  // raw values last seen, to warn once per change
    std::array<float, kChunk> scratch{};
    LV2_URID midi_event = 0;
    LV2_Log_Logger logger{};

    float control(uint32_t port) {
        const float raw = *controls[port];
        const Control& c = kControls[port];
        const float value = std::isnan(raw) ? c.low : std::clamp(raw, c.low, c.high);
        if (raw != last[port] && !(std::isnan(raw) && std::isnan(last[port])) && value != raw)
            lv2_log_warning(&logger, "fretbuzz: %s = %g is out of range [%g, %g]; using %g\n", c.name,
                            static_cast<double>(raw), static_cast<double>(c.low), static_cast<double>(c.high),
                            static_cast<double>(value));
        last[port] = raw;
        return value;
    }

    void sync(const std::array<float, kPortCount>& now) {
        Engine& e = *engine;
        if (now[kPickup] != applied[kPickup]) e.set_pickup(now[kPickup] * e.length_m());
        if (now[kBuzz] != applied[kBuzz]) e.set_obstacle_offset(now[kBuzz] * 1e-3);
        if (now[kDamping] != applied[kDamping]) e.set_damping_scale(now[kDamping]);
        applied = now;
    }

    void note_on(int note, int velocity, const std::array<float, kPortCount>& now) {
        const int fret = note - open_note;
        if (fret < 0 || fret > engine->fret_count()) return;  // not on this string
        sync(now);
        Engine& e = *engine;
        e.mute(false);
        e.finger_down(fret);  // moves the finger from the last note's fret; 0 lifts it
        const double stop = e.fret_position_m(fret);
        e.strike({stop + now[kPluck] * (e.length_m() - stop), kFullStrength * velocity / 127.0, 0.01, false});
        held = note;
        active = true;
    }

    void note_off(int note) {
        if (note != held) return;  // a later note took the string over
        engine->mute(true);
        engine->finger_up();
        held = -1;
    }

    void render(uint32_t from, uint32_t to) {
        while (from < to && active) {
            const uint32_t n = std::min<uint32_t>(to - from, kChunk);
            const std::span<float> chunk(scratch.data(), n);
            engine->process(chunk);
            for (uint32_t i = 0; i < n; ++i) out[from + i] += chunk[i];
            if (held < 0 && !engine->sounding()) active = false;
            from += n;
        }
    }

    void run(uint32_t frames) {
        if (latency != nullptr) *latency = latency_samples;
        std::fill(out, out + frames, 0.0f);
        std::array<float, kPortCount> now{};
        for (uint32_t p = kPluck; p < kPortCount; ++p) now[p] = control(p);
        if (active) sync(now);
        uint32_t done = 0;
        LV2_ATOM_SEQUENCE_FOREACH(midi, ev) {
            if (ev->body.type != midi_event) continue;
            const auto* msg = reinterpret_cast<const uint8_t*>(ev + 1);
            const auto at = static_cast<uint32_t>(std::clamp<int64_t>(ev->time.frames, done, frames));
            render(done, at);
            done = at;
            const uint8_t status = lv2_midi_message_type(msg);
            if (status == LV2_MIDI_MSG_NOTE_ON && msg[2] > 0)
                note_on(msg[1], msg[2], now);
            else if (status == LV2_MIDI_MSG_NOTE_OFF || status == LV2_MIDI_MSG_NOTE_ON)
                note_off(msg[1]);
        }
        render(done, frames);
    }
};

LV2_Handle instantiate(const LV2_Descriptor* descriptor, double rate, const char*, const LV2_Feature* const* features) {
    LV2_URID_Map* map = nullptr;
    LV2_Log_Log* log = nullptr;
    for (int i = 0; features != nullptr && features[i] != nullptr; ++i) {
        if (std::strcmp(features[i]->URI, LV2_URID__map) == 0) map = static_cast<LV2_URID_Map*>(features[i]->data);
        if (std::strcmp(features[i]->URI, LV2_LOG__log) == 0) log = static_cast<LV2_Log_Log*>(features[i]->data);
    }
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
        // At most 4x oversampling: a host may run six of these (six strings) on one core
        // (bench/bench_realtime.cpp, guitar_chord_6_voices_M4).
        options.max_oversampling = 4;
        instrument->engine = std::make_unique<Engine>(open, options);
        instrument->applied = {0, 0, -1, -1, 0, 1};  // the engine's own pickup; buzz 0; damping 1
        // Whole frames, as hosts compensate them (the filter's delay is (length - 1) / 2M).
        instrument->latency_samples = static_cast<float>(std::round(instrument->engine->latency_samples()));
    } catch (const std::exception& e) {
        lv2_log_error(&instrument->logger, "fretbuzz: cannot prepare %s: %s\n", descriptor->URI, e.what());
        return nullptr;
    }
    instrument->last = {0.0f, 0.0f, 0.8f, 0.9f, 0.0f, 1.0f};  // the .ttl defaults
    return instrument.release();
}

void connect_port(LV2_Handle handle, uint32_t port, void* data) {
    auto* self = static_cast<Instrument*>(handle);
    if (port == kMidiIn)
        self->midi = static_cast<const LV2_Atom_Sequence*>(data);
    else if (port == kOut)
        self->out = static_cast<float*>(data);
    else if (port < kPortCount)
        self->controls[port] = static_cast<const float*>(data);
    else if (port == kLatencyPort)
        self->latency = static_cast<float*>(data);
}

void run(LV2_Handle handle, uint32_t frames) { static_cast<Instrument*>(handle)->run(frames); }

void cleanup(LV2_Handle handle) { delete static_cast<Instrument*>(handle); }

const void* extension_data(const char*) { return nullptr; }

constexpr LV2_Descriptor descriptor(const char* uri) {
    return {uri, instantiate, connect_port, nullptr, run, nullptr, cleanup, extension_data};
}
const std::array<LV2_Descriptor, kPresets.size()> kDescriptors = {
    descriptor(kPresets[0].uri), descriptor(kPresets[1].uri), descriptor(kPresets[2].uri), descriptor(kPresets[3].uri)};

}  // namespace

LV2_SYMBOL_EXPORT const LV2_Descriptor* lv2_descriptor(uint32_t index) {
    return index < kDescriptors.size() ? &kDescriptors[index] : nullptr;
}
