// The LV2 instrument loaded headless through lilv from the build tree, as a host would: a MIDI
// note sounds at the string's pitch for its fret, note-off mutes it, run() never allocates,
// and out-of-range controls are clamped with a logged warning.
#include <gtest/gtest.h>
#include <lilv/lilv.h>
#include <lv2/atom/atom.h>
#include <lv2/atom/util.h>
#include <lv2/log/log.h>
#include <lv2/midi/midi.h>
#include <lv2/urid/urid.h>

#include <cmath>
#include <cstdarg>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <string>
#include <vector>

#include "AllocationCounter.hpp"
#include "Pitch.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/realtime/Performance.hpp"

namespace {

std::vector<std::string>& uris() {
    static std::vector<std::string> table;
    return table;
}
LV2_URID map_uri(LV2_URID_Map_Handle, const char* uri) {
    for (std::size_t i = 0; i < uris().size(); ++i)
        if (uris()[i] == uri) return static_cast<LV2_URID>(i + 1);
    uris().emplace_back(uri);
    return static_cast<LV2_URID>(uris().size());
}

int warnings = 0;
int log_vprintf(LV2_Log_Handle, LV2_URID type, const char* fmt, va_list args) {
    if (type == map_uri(nullptr, LV2_LOG__Warning)) ++warnings;
    return std::vfprintf(stderr, fmt, args);
}
int log_printf(LV2_Log_Handle handle, LV2_URID type, const char* fmt, ...) {
    va_list args;
    va_start(args, fmt);
    const int n = log_vprintf(handle, type, fmt, args);
    va_end(args);
    return n;
}

// An atom sequence holding MIDI messages, rebuilt for every run() call.
struct MidiBuffer {
    alignas(8) unsigned char bytes[4096];
    LV2_Atom_Sequence* seq() { return reinterpret_cast<LV2_Atom_Sequence*>(bytes); }
    void clear() {
        seq()->atom.type = map_uri(nullptr, LV2_ATOM__Sequence);
        seq()->atom.size = sizeof(LV2_Atom_Sequence_Body);
        seq()->body.unit = 0;
        seq()->body.pad = 0;
    }
    void add(int64_t frame, unsigned char status, unsigned char note, unsigned char velocity) {
        const std::size_t at = sizeof(LV2_Atom) + seq()->atom.size;
        LV2_Atom_Event ev{};
        ev.time.frames = frame;
        ev.body.type = map_uri(nullptr, LV2_MIDI__MidiEvent);
        ev.body.size = 3;
        const unsigned char msg[3] = {status, note, velocity};
        std::memcpy(bytes + at, &ev, sizeof ev);
        std::memcpy(bytes + at + sizeof ev, msg, sizeof msg);
        seq()->atom.size += static_cast<uint32_t>(lv2_atom_pad_size(sizeof(LV2_Atom_Event) + 3));
    }
};

class PluginHost {
public:
    explicit PluginHost(const char* uri, double rate) : rate_(rate) {
        setenv("LV2_PATH", FRETBUZZ_LV2_PATH ":/usr/lib/lv2", 1);
        world_ = lilv_world_new();
        lilv_world_load_all(world_);
        LilvNode* node = lilv_new_uri(world_, uri);
        plugin_ = lilv_plugins_get_by_uri(lilv_world_get_all_plugins(world_), node);
        lilv_node_free(node);
        if (plugin_ == nullptr) return;
        features_ = {&map_feature_, &log_feature_, nullptr};
        instance_ = lilv_plugin_instantiate(plugin_, rate, features_.data());
        if (instance_ == nullptr) return;
        controls_ = {0.0f, 0.0f, 0.8f, 0.9f, 0.0f, 1.0f};
        midi_.clear();
        lilv_instance_connect_port(instance_, 0, midi_.bytes);
        for (uint32_t p = 2; p < 6; ++p) lilv_instance_connect_port(instance_, p, &controls_[p]);
        lilv_instance_connect_port(instance_, 6, &latency_);
        lilv_instance_activate(instance_);
    }
    ~PluginHost() {
        if (instance_ != nullptr) {
            lilv_instance_deactivate(instance_);
            lilv_instance_free(instance_);
        }
        lilv_world_free(world_);
    }
    bool ready() const { return instance_ != nullptr; }
    MidiBuffer& midi() { return midi_; }
    float& control(uint32_t port) { return controls_[port]; }
    float latency() const { return latency_; }  // the latency port, as the last run left it
    // Runs `frames` samples in blocks of 256 (events go in the first block), appending to out.
    void run(std::size_t frames, std::vector<float>& out) {
        for (std::size_t done = 0; done < frames; done += 256) {
            const std::size_t n = std::min<std::size_t>(256, frames - done);
            const std::size_t at = out.size();
            out.resize(at + n);
            lilv_instance_connect_port(instance_, 1, out.data() + at);
            {
                const fretbuzz::testing::Counting counting;
                lilv_instance_run(instance_, static_cast<uint32_t>(n));
            }
            midi_.clear();
        }
    }

private:
    double rate_;
    LilvWorld* world_ = nullptr;
    const LilvPlugin* plugin_ = nullptr;
    LilvInstance* instance_ = nullptr;
    LV2_URID_Map map_{nullptr, map_uri};
    LV2_Log_Log log_{nullptr, log_printf, log_vprintf};
    LV2_Feature map_feature_{LV2_URID__map, &map_};
    LV2_Feature log_feature_{LV2_LOG__log, &log_};
    std::vector<const LV2_Feature*> features_;
    std::vector<float> controls_;
    float latency_ = -1.0f;
    MidiBuffer midi_;
};

using fretbuzz::testing::partial_near;
using fretbuzz::testing::rms;

TEST(Lv2Plugin, NoteSoundsAtItsPitchAndNoteOffMutesIt) {
    const double rate = 48000.0;
    PluginHost host("urn:fretbuzz:guitar", rate);
    ASSERT_TRUE(host.ready());
    const fretbuzz::Case open = fretbuzz::load_case("guitar-point");
    const int fret = 5;
    const auto note = static_cast<unsigned char>(fretbuzz::open_string_note(open) + fret);
    const double expected = open.modes.frequency_hz.front() * std::exp2(fret / 12.0);
    // The obstacle (a point level with the string at mid-length) lowered 2 mm: no contact, so
    // the pitch is the stopped string's own. (Touching it raises the pitch: that is the buzz.)
    host.control(4) = -2.0f;
    const long before = fretbuzz::testing::allocations();
    std::vector<float> out;
    host.midi().add(0, LV2_MIDI_MSG_NOTE_ON, note, 100);
    host.run(48000, out);  // 1 s held
    host.midi().add(0, LV2_MIDI_MSG_NOTE_OFF, note, 0);
    host.run(24000, out);  // 0.5 s after note-off
    EXPECT_EQ(fretbuzz::testing::allocations() - before, 0);
    for (float y : out) ASSERT_TRUE(std::isfinite(y));
    const double f = partial_near(out, 4800, 48000, rate, expected);
    EXPECT_LT(std::abs(1200.0 * std::log2(f / expected)), 5.0) << f << " Hz, expected " << expected;
    const double held = rms(out, 4800, 48000);
    EXPECT_GT(held, 1e-4);
    EXPECT_LT(rms(out, 60000, 72000), 1e-3 * held);
    // The host is told the decimation filter's delay (whole frames): the guitar runs at 4x.
    fretbuzz::EngineOptions options;
    options.host_rate_hz = rate;
    options.max_oversampling = 4;
    const fretbuzz::Engine engine(open, options);
    EXPECT_GT(engine.latency_samples(), 0.0);
    EXPECT_EQ(host.latency(), std::round(engine.latency_samples()));
}

TEST(Lv2Plugin, ClampsOutOfRangeControlsWithAWarning) {
    PluginHost host("urn:fretbuzz:tanpura", 48000.0);
    ASSERT_TRUE(host.ready());
    const int before = warnings;
    host.control(2) = 5.0f;        // pluck position beyond the string
    host.control(4) = -100.0f;     // buzz far below its range
    host.control(5) = std::nanf("");
    std::vector<float> out;
    host.midi().add(0, LV2_MIDI_MSG_NOTE_ON, static_cast<unsigned char>(fretbuzz::open_string_note(fretbuzz::load_case("tanpura"))), 127);
    host.run(4800, out);
    EXPECT_GE(warnings - before, 3);
    double energy = 0.0;
    for (float y : out) {
        ASSERT_TRUE(std::isfinite(y));
        energy += static_cast<double>(y) * y;
    }
    EXPECT_GT(energy, 0.0);
}

}  // namespace
