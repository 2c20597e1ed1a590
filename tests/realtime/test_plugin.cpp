// The LV2 instrument loaded headless through lilv from the build tree, as a host would: a MIDI
// note sounds at the string's pitch for its fret, note-off mutes it, run() never allocates
// (not under storms of 1000 note-ons a block with every control at its extremes either), a
// storm costs about what a chord does, every control value gives a usable instrument, each
// plugin has presets and its ports units, and out-of-range controls are clamped with a
// logged warning.
#include <gtest/gtest.h>
#include <lilv/lilv.h>
#include <lv2/atom/atom.h>
#include <lv2/atom/util.h>
#include <lv2/log/log.h>
#include <lv2/midi/midi.h>
#include <lv2/presets/presets.h>
#include <lv2/units/units.h>
#include <lv2/urid/urid.h>
#include <time.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdarg>
#include <cstdlib>
#include <cstring>
#include <map>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "AllocationCounter.hpp"
#include "Pitch.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/StringsCaseFile.hpp"
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

// An atom sequence holding MIDI messages, rebuilt for every run() call; room for 2000 events.
struct MidiBuffer {
    alignas(8) unsigned char bytes[65536];
    LV2_Atom_Sequence* seq() { return reinterpret_cast<LV2_Atom_Sequence*>(bytes); }
    void clear() {
        seq()->atom.type = map_uri(nullptr, LV2_ATOM__Sequence);
        seq()->atom.size = sizeof(LV2_Atom_Sequence_Body);
        seq()->body.unit = 0;
        seq()->body.pad = 0;
    }
    void add(int64_t frame, unsigned char status, unsigned char note, unsigned char velocity) {
        const std::size_t at = sizeof(LV2_Atom) + seq()->atom.size;
        const auto size = static_cast<uint32_t>(lv2_atom_pad_size(sizeof(LV2_Atom_Event) + 3));
        if (at + size > sizeof bytes) std::abort();
        LV2_Atom_Event ev{};
        ev.time.frames = frame;
        ev.body.type = map_uri(nullptr, LV2_MIDI__MidiEvent);
        ev.body.size = 3;
        const unsigned char msg[3] = {status, note, velocity};
        std::memcpy(bytes + at, &ev, sizeof ev);
        std::memcpy(bytes + at + sizeof ev, msg, sizeof msg);
        seq()->atom.size += size;
    }
};

double thread_seconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

class PluginHost {
public:
    // `controls` control inputs from port 2 on, then the latency output.
    explicit PluginHost(const char* uri, double rate, uint32_t controls = 4) : rate_(rate) {
        // FRETBUZZ_TEST_LV2_PATH, if set, runs these checks against another build's bundle.
        const char* other = std::getenv("FRETBUZZ_TEST_LV2_PATH");
        setenv("LV2_PATH", (std::string(other != nullptr ? other : FRETBUZZ_LV2_PATH) + ":/usr/lib/lv2").c_str(), 1);
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
        for (uint32_t p = 2; p < 2 + controls; ++p) lilv_instance_connect_port(instance_, p, &controls_[p]);
        lilv_instance_connect_port(instance_, 2 + controls, &latency_);
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
    // Runs `frames` samples in blocks of `block` (events go in the first block), appending to
    // out; returns the thread CPU time of the longest block.
    double run(std::size_t frames, std::vector<float>& out, std::size_t block = 256) {
        double longest = 0.0;
        for (std::size_t done = 0; done < frames; done += block) {
            const std::size_t n = std::min<std::size_t>(block, frames - done);
            const std::size_t at = out.size();
            out.resize(at + n);
            lilv_instance_connect_port(instance_, 1, out.data() + at);
            const double start = thread_seconds();
            {
                const fretbuzz::testing::Counting counting;
                lilv_instance_run(instance_, static_cast<uint32_t>(n));
            }
            longest = std::max(longest, thread_seconds() - start);
            midi_.clear();
        }
        return longest;
    }
    LilvWorld* world() const { return world_; }
    const LilvPlugin* plugin() const { return plugin_; }
    LV2_URID_Map* map() { return &map_; }

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


// The four plugins and the case each plays.
struct Instrument {
    const char* uri;
    const char* case_name;
};
constexpr std::array<Instrument, 4> kInstruments = {{{"urn:fretbuzz:bass", "bass-pluck"},
                                                    {"urn:fretbuzz:guitar", "guitar-point"},
                                                    {"urn:fretbuzz:sitar", "sitar"},
                                                    {"urn:fretbuzz:tanpura", "tanpura"}}};

// The control ports as the .ttl declares them: index, symbol, range, default.
struct ControlPort {
    uint32_t port;
    const char* symbol;
    float low, high, value;
};
constexpr std::array<ControlPort, 4> kControlPorts = {{{2, "pluck", 0.02f, 0.98f, 0.8f},
                                                       {3, "pickup", 0.02f, 0.98f, 0.9f},
                                                       {4, "buzz", -2.0f, 0.5f, 0.0f},
                                                       {5, "damping", 0.1f, 10.0f, 1.0f}}};

void set_controls(PluginHost& host, int which) {  // 0: defaults, 1: every low end, 2: every high end
    for (const ControlPort& c : kControlPorts) host.control(c.port) = which == 0 ? c.value : which == 1 ? c.low : c.high;
}

// `count` note-ons (or -offs) on random keys from `lowest` (`keys` of them) at random frames
// of a block of `frames`, in time order.
void storm(PluginHost& host, std::mt19937& random, int count, uint32_t frames, unsigned char status, int lowest = 0,
           int keys = 128) {
    std::vector<int64_t> at(static_cast<std::size_t>(count));
    for (int64_t& f : at) f = static_cast<int64_t>(random() % frames);
    std::sort(at.begin(), at.end());
    for (const int64_t f : at)
        host.midi().add(f, status, static_cast<unsigned char>(lowest + static_cast<int>(random() % static_cast<unsigned>(keys))),
                        static_cast<unsigned char>(status == LV2_MIDI_MSG_NOTE_ON ? 1 + random() % 127 : 0));
}

TEST(Lv2Plugin, RunNeverAllocatesUnderNoteStorms) {
    std::mt19937 random(37);
    for (const Instrument& instrument : kInstruments) {
        SCOPED_TRACE(instrument.uri);
        PluginHost host(instrument.uri, 48000.0);
        ASSERT_TRUE(host.ready());
        const long before = fretbuzz::testing::allocations();
        std::vector<float> out;
        for (int setting : {0, 1, 2, 0, 2}) {
            set_controls(host, setting);
            storm(host, random, 1000, 256, LV2_MIDI_MSG_NOTE_ON);
            host.run(256, out);
            storm(host, random, 500, 64, LV2_MIDI_MSG_NOTE_OFF);
            storm(host, random, 500, 64, LV2_MIDI_MSG_NOTE_ON);
            host.run(64, out, 64);
            host.run(2048, out);
        }
        EXPECT_EQ(fretbuzz::testing::allocations() - before, 0);
        for (float y : out) ASSERT_TRUE(std::isfinite(y));
    }
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

// A block with 1000 note-ons (on the instrument's 25 keys) costs about what a block with a
// six-note chord does: the plugin starts at most six notes a block (the last six; earlier ones
// would be taken for later ones within the block anyway) and sounds at most six voices.
TEST(Lv2Plugin, NoteStormCostsAboutWhatAChordDoes) {
    std::mt19937 random(38);
    for (const Instrument& instrument : {kInstruments[0], kInstruments[1]}) {
        SCOPED_TRACE(instrument.uri);
        PluginHost host(instrument.uri, 48000.0);
        ASSERT_TRUE(host.ready());
        const int open = fretbuzz::open_string_note(fretbuzz::load_case(instrument.case_name));
        std::vector<double> chord, stormy, buzzing;
        std::vector<float> out;
        const auto all_off = [&] {
            for (int key = open; key < open + 25; ++key) host.midi().add(0, LV2_MIDI_MSG_NOTE_OFF, static_cast<unsigned char>(key), 0);
            host.run(24000, out);  // muted voices die away
        };
        for (int repeat = 0; repeat < 5; ++repeat) {
            for (int fret : {0, 2, 4, 5, 7, 9})
                host.midi().add(0, LV2_MIDI_MSG_NOTE_ON, static_cast<unsigned char>(open + fret), 100);
            chord.push_back(host.run(256, out));
            all_off();
            storm(host, random, 1000, 256, LV2_MIDI_MSG_NOTE_ON, open, 25);
            stormy.push_back(host.run(256, out));
            all_off();
            // The chord again with the frets or bridge raised as far as the buzz control goes.
            host.control(4) = 0.5f;
            for (int fret : {0, 2, 4, 5, 7, 9})
                host.midi().add(0, LV2_MIDI_MSG_NOTE_ON, static_cast<unsigned char>(open + fret), 100);
            buzzing.push_back(host.run(4096, out));  // its longest block
            all_off();
            host.control(4) = 0.0f;
        }
        std::printf("%s: the chord's longest block with buzz at its maximum %.2f ms\n", instrument.uri, 1e3 * median(buzzing));
        std::printf("%s: a chord's block %.2f ms, a storm's %.2f ms (thread CPU time, medians of 5; a block lasts 5.33 ms)\n",
                    instrument.uri, 1e3 * median(chord), 1e3 * median(stormy));
        EXPECT_LT(median(stormy), 2.0 * median(chord));
        // Raised as far as the control goes, the frets or bridge stop at the string's rest line:
        // the strings buzz on them, and cost little more (raised into the strings, 9 times more).
        EXPECT_LT(median(buzzing), 3.0 * median(chord));
    }
}

// The peak of the first 0.5 s of a note, which is then muted and left to die away.
double note_peak(PluginHost& host, unsigned char note) {
    std::vector<float> out;
    host.midi().add(0, LV2_MIDI_MSG_NOTE_ON, note, 100);
    host.run(24000, out);
    host.midi().add(0, LV2_MIDI_MSG_NOTE_OFF, note, 0);
    std::vector<float> rest;
    host.run(48000, rest);
    double peak = 0.0;
    for (float y : out) peak = std::max(peak, std::abs(static_cast<double>(y)));
    return peak;
}

// Each control over its whole declared range, the others at their defaults: the peak of a
// note stays within a factor kUsable of the defaults' either way (buzz at its maximum, raising
// the frets or bridge into the string, once gave 140-3900 times).
constexpr double kUsable = 4.0;

TEST(Lv2Plugin, EveryControlValueGivesAUsableInstrument) {
    for (const Instrument& instrument : kInstruments) {
        SCOPED_TRACE(instrument.uri);
        PluginHost host(instrument.uri, 48000.0);
        ASSERT_TRUE(host.ready());
        const auto note = static_cast<unsigned char>(fretbuzz::open_string_note(fretbuzz::load_case(instrument.case_name)) + 5);
        set_controls(host, 0);
        const double reference = note_peak(host, note);
        ASSERT_GT(reference, 0.0);
        for (const ControlPort& c : kControlPorts) {
            std::string line;
            for (int k = 0; k <= 5; ++k) {
                const float value = c.low + (c.high - c.low) * static_cast<float>(k) / 5.0f;
                set_controls(host, 0);
                host.control(c.port) = value;
                const double ratio = note_peak(host, note) / reference;
                char entry[64];
                std::snprintf(entry, sizeof entry, " %g: %.3g", static_cast<double>(value), ratio);
                line += entry;
                EXPECT_LT(ratio, kUsable) << c.symbol << " = " << value;
                EXPECT_GT(ratio, 1.0 / kUsable) << c.symbol << " = " << value;
            }
            std::printf("%s %s (peak / default's):%s\n", instrument.uri, c.symbol, line.c_str());
        }
    }
}

// Each plugin has the presets "clean", "buzzy" and "dark" (values within the ports' ranges,
// each a usable instrument), and its controls carry units.
TEST(Lv2Plugin, HasPresetsAndUnits) {
    for (const Instrument& instrument : kInstruments) {
        SCOPED_TRACE(instrument.uri);
        PluginHost host(instrument.uri, 48000.0);
        ASSERT_TRUE(host.ready());
        LilvWorld* world = host.world();
        LilvNode* preset_class = lilv_new_uri(world, LV2_PRESETS__Preset);
        LilvNode* label = lilv_new_uri(world, LILV_NS_RDFS "label");
        LilvNode* unit = lilv_new_uri(world, LV2_UNITS__unit);
        for (const ControlPort& c : kControlPorts) {
            const LilvPort* port = lilv_plugin_get_port_by_index(host.plugin(), c.port);
            LilvNodes* units = lilv_port_get_value(host.plugin(), port, unit);
            EXPECT_EQ(lilv_nodes_size(units), 1u) << c.symbol;
            lilv_nodes_free(units);
        }
        const auto note = static_cast<unsigned char>(fretbuzz::open_string_note(fretbuzz::load_case(instrument.case_name)) + 5);
        set_controls(host, 0);
        const double reference = note_peak(host, note);
        std::vector<std::string> names;
        LilvNodes* presets = lilv_plugin_get_related(host.plugin(), preset_class);
        LILV_FOREACH(nodes, i, presets) {
            const LilvNode* preset = lilv_nodes_get(presets, i);
            lilv_world_load_resource(world, preset);
            LilvNodes* labels = lilv_world_find_nodes(world, preset, label, nullptr);
            ASSERT_EQ(lilv_nodes_size(labels), 1u);
            names.emplace_back(lilv_node_as_string(lilv_nodes_get_first(labels)));
            lilv_nodes_free(labels);
            LilvState* state = lilv_state_new_from_world(world, host.map(), preset);
            ASSERT_NE(state, nullptr);
            std::map<std::string, float> values;
            lilv_state_emit_port_values(
                state,
                [](const char* symbol, void* data, const void* value, uint32_t size, uint32_t) {
                    if (size == sizeof(float)) (*static_cast<std::map<std::string, float>*>(data))[symbol] = *static_cast<const float*>(value);
                },
                &values);
            lilv_state_free(state);
            EXPECT_EQ(values.size(), kControlPorts.size()) << names.back();
            set_controls(host, 0);
            for (const ControlPort& c : kControlPorts) {
                ASSERT_TRUE(values.count(c.symbol)) << names.back() << ": " << c.symbol;
                EXPECT_GE(values[c.symbol], c.low) << names.back() << ": " << c.symbol;
                EXPECT_LE(values[c.symbol], c.high) << names.back() << ": " << c.symbol;
                host.control(c.port) = values[c.symbol];
            }
            const double ratio = note_peak(host, note) / reference;
            EXPECT_GT(ratio, 1.0 / kUsable) << names.back();
            EXPECT_LT(ratio, kUsable) << names.back();
        }
        lilv_nodes_free(presets);
        std::sort(names.begin(), names.end());
        EXPECT_EQ(names, (std::vector<std::string>{"buzzy", "clean", "dark"}));
        lilv_node_free(preset_class);
        lilv_node_free(label);
        lilv_node_free(unit);
    }
}

}  // namespace

// The strings on one bridge (BridgeEngine): a note is struck on the string that plays it (the
// guitar's finger put down behind the fret first), the chord sounds, run() never allocates,
// and the host is told the latency. The sitar's main string rings, its taraf take it up.
TEST(Lv2Plugin, StringsOnABridgePlayNotesAndChords) {
    const double rate = 48000.0;
    {
        PluginHost host("urn:fretbuzz:guitar-chord", rate, 1);
        ASSERT_TRUE(host.ready());
        const fretbuzz::StringsCase sc = fretbuzz::parse_strings_case(*fretbuzz::read_strings_case_text("guitar-chord"));
        const int g3 = fretbuzz::open_string_note(sc.strings[3]);
        // A3 is fret 2 of the G string (the highest string that reaches it).
        const double expected = sc.strings[3].modes.frequency_hz.front() * std::exp2(2.0 / 12.0);
        const long before = fretbuzz::testing::allocations();
        std::vector<float> out;
        host.run(4800, out);
        host.midi().add(0, LV2_MIDI_MSG_NOTE_ON, static_cast<unsigned char>(g3 + 2), 100);
        host.run(48000, out);
        EXPECT_GT(host.latency(), 0.0f);
        const double f = partial_near(out, 9600, 52800, rate, expected);
        std::printf("guitar-chord: A3 on the G string at %.2f Hz (%+.1f cents from 2 frets above the open string)\n", f,
                    1200.0 * std::log2(f / expected));
        EXPECT_LT(std::abs(1200.0 * std::log2(f / expected)), 20.0);
        // An E major chord, E2 B2 E3 G#3 B3 E4, struck together; then released.
        for (const int note : {40, 47, 52, 56, 59, 64}) host.midi().add(0, LV2_MIDI_MSG_NOTE_ON, static_cast<unsigned char>(note), 90);
        host.run(24000, out);
        for (const int note : {40, 47, 52, 56, 59, 64}) host.midi().add(0, LV2_MIDI_MSG_NOTE_OFF, static_cast<unsigned char>(note), 0);
        host.run(4800, out);
        EXPECT_EQ(fretbuzz::testing::allocations() - before, 0);
        for (float y : out) ASSERT_TRUE(std::isfinite(y));
        EXPECT_GT(rms(out, 52800, 76800), 1e-4);
        // Released, every string is muted: 50 ms later the chord has died away.
        std::printf("guitar-chord: rms %.3e while held, %.3e 50 ms after the release\n", rms(out, 52800, 76800),
                    rms(out, 79200, 81600));
        EXPECT_LT(rms(out, 79200, 81600), 0.01 * rms(out, 52800, 76800));
    }
    {
        PluginHost host("urn:fretbuzz:sitar-taraf", rate, 1);
        ASSERT_TRUE(host.ready());
        const fretbuzz::StringsCase sc = fretbuzz::parse_strings_case(*fretbuzz::read_strings_case_text("sitar-taraf"));
        const long before = fretbuzz::testing::allocations();
        std::vector<float> out;
        host.midi().add(0, LV2_MIDI_MSG_NOTE_ON, static_cast<unsigned char>(fretbuzz::open_string_note(sc.strings[0])), 110);
        host.run(24000, out);
        host.midi().add(0, LV2_MIDI_MSG_NOTE_ON, 20, 110);  // no string's note: nothing
        host.run(4800, out);
        EXPECT_EQ(fretbuzz::testing::allocations() - before, 0);
        for (float y : out) ASSERT_TRUE(std::isfinite(y));
        const double f1 = sc.strings[0].modes.frequency_hz.front();
        EXPECT_GT(rms(out, 4800, 24000), 1e-4);
        const double f = partial_near(out, 4800, 28800, rate, f1);
        EXPECT_LT(std::abs(1200.0 * std::log2(f / f1)), 20.0) << f << " Hz, expected " << f1;
    }
}
