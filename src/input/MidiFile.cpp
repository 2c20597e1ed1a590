#include "fretbuzz/input/MidiFile.hpp"

#include <smf.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/TextFile.hpp"

namespace fretbuzz {

namespace {

// A track's delta times add up to at most this many ticks (the largest delta time a 4-byte
// variable-length number holds; far beyond an hour at any usual resolution): libsmf keeps
// ticks in an int.
constexpr std::uint32_t kMaxTrackTicks = 0x0FFFFFFF;

std::string hex(unsigned value) {
    char text[8];
    std::snprintf(text, sizeof text, "0x%02X", value);
    return text;
}

std::uint32_t big_endian(std::string_view bytes, std::size_t at, std::size_t count) {
    std::uint32_t v = 0;
    for (std::size_t k = 0; k < count; ++k) v = (v << 8) | static_cast<unsigned char>(bytes[at + k]);
    return v;
}

void put_number(std::vector<unsigned char>& out, std::uint32_t v) {  // a variable-length number
    unsigned char groups[4];
    int count = 0;
    do {
        groups[count++] = static_cast<unsigned char>(v & 0x7F);
        v >>= 7;
    } while (v > 0);
    while (count > 1) out.push_back(static_cast<unsigned char>(groups[--count] | 0x80));
    out.push_back(groups[0]);
}

void put_big_endian(std::vector<unsigned char>& out, std::uint32_t v, int count) {
    for (int k = count - 1; k >= 0; --k) out.push_back(static_cast<unsigned char>(v >> (8 * k)));
}

// Walks one MTrk chunk's events, checking each, and writes the ones fretbuzz reads (note-ons
// and -offs, tempo changes, End of Track) as libsmf reads them: every event with its status
// byte, meta lengths in one byte. Errors name the track and the byte offset in the file.
class TrackReader {
public:
    TrackReader(std::string_view file, std::size_t begin, std::size_t end, std::string where)
        : file_(file), at_(begin), end_(end), where_(std::move(where)) {}

    std::vector<unsigned char> read() {
        std::vector<unsigned char> out;
        std::uint32_t ticks = 0;
        std::uint32_t pending = 0;  // ticks since the last event written
        unsigned running = 0;       // the status that data bytes continue; 0: none
        bool ended = false;
        const auto put = [&](std::initializer_list<unsigned char> event) {
            put_number(out, pending);
            out.insert(out.end(), event);
            pending = 0;
        };
        while (at_ < end_) {
            if (ended) fail(at_, "bytes after End of Track");
            const std::size_t event_at = at_;
            const std::uint32_t delta = number("a delta time");
            if (delta > kMaxTrackTicks - ticks)
                fail(event_at, "the track lasts more than " + std::to_string(kMaxTrackTicks) + " ticks");
            ticks += delta;
            pending += delta;
            unsigned status = peek("an event");
            if (status & 0x80) {
                ++at_;
            } else if (running == 0) {
                fail(at_, "data byte " + hex(status) +
                              " where a status byte is due (running status continues channel messages only, not "
                              "a sysex or meta event, and not at a track's start)");
            } else {
                status = running;
            }
            if (status < 0xF0) {  // a channel message: one or two data bytes
                const unsigned type = status & 0xF0;
                const int count = type == 0xC0 || type == 0xD0 ? 1 : 2;
                unsigned char data[2] = {0, 0};
                for (int k = 0; k < count; ++k) {
                    const std::size_t data_at = at_;
                    data[k] = next("a channel message");
                    if (data[k] & 0x80)
                        fail(data_at, "byte " + hex(data[k]) + " inside a channel message (data bytes are below 0x80)");
                }
                running = status;
                if (type == 0x80 || type == 0x90) put({static_cast<unsigned char>(status), data[0], data[1]});
            } else if (status == 0xF0 || status == 0xF7) {  // sysex: a length, then that many bytes
                running = 0;
                skip(number("a sysex length"), "a sysex message");
            } else if (status == 0xFF) {
                running = 0;
                const unsigned type = next("a meta event");
                if (type & 0x80) fail(at_ - 1, "meta event type " + hex(type) + " (types are below 0x80)");
                const std::uint32_t length = number("a meta event's length");
                const std::size_t data_at = at_;
                skip(length, "a meta event");
                if (type == 0x2F) {
                    if (length != 0) fail(data_at, "End of Track with " + std::to_string(length) + " data bytes (it has none)");
                    ended = true;
                    put({0xFF, 0x2F, 0x00});
                } else if (type == 0x51) {
                    if (length != 3)
                        fail(data_at, "a tempo change with " + std::to_string(length) + " data bytes (it has 3)");
                    const std::uint32_t tempo = big_endian(file_, data_at, 3);
                    if (tempo == 0) fail(data_at, "a tempo of 0 microseconds per quarter note");
                    put({0xFF, 0x51, 0x03, static_cast<unsigned char>(tempo >> 16), static_cast<unsigned char>(tempo >> 8),
                         static_cast<unsigned char>(tempo)});
                }
            } else {
                fail(event_at, "status byte " + hex(status) +
                                   " (a system common or real-time message, which has no place in a MIDI file)");
            }
        }
        if (!ended) fail(end_, "the track has no End of Track event");
        return out;
    }

private:
    [[noreturn]] void fail(std::size_t at, const std::string& what) const {
        throw InputError(where_ + ", byte " + std::to_string(at) + ": " + what);
    }
    unsigned peek(const char* what) const {
        if (at_ >= end_) fail(at_, std::string("the track ends inside ") + what);
        return static_cast<unsigned char>(file_[at_]);
    }
    unsigned char next(const char* what) {
        const unsigned b = peek(what);
        ++at_;
        return static_cast<unsigned char>(b);
    }
    std::uint32_t number(const char* what) {  // a variable-length number: at most 4 bytes
        const std::size_t start = at_;
        std::uint32_t v = 0;
        for (int k = 0; k < 4; ++k) {
            const unsigned char b = next(what);
            v = (v << 7) | (b & 0x7Fu);
            if (!(b & 0x80)) return v;
        }
        fail(start, std::string(what) + " longer than 4 bytes");
    }
    void skip(std::uint32_t count, const char* what) {
        if (count > end_ - at_)
            fail(at_, std::string(what) + " of " + std::to_string(count) + " bytes runs past the track's end (" +
                          std::to_string(end_ - at_) + " bytes left)");
        at_ += count;
    }

    std::string_view file_;
    std::size_t at_, end_;
    std::string where_;
};

// The file checked chunk by chunk, rewritten as what libsmf reads safely: a format-1 header
// and one MTrk per track holding only the events fretbuzz uses.
std::vector<unsigned char> checked_copy(std::string_view file, const std::string& source) {
    const auto fail = [&](const std::string& what) { throw InputError(source + ": " + what); };
    if (file.size() < 14)
        fail("is too short for a standard MIDI file (" + std::to_string(file.size()) + " bytes; its header alone has 14)");
    if (file.substr(0, 4) != "MThd") fail("does not start with \"MThd\": it is not a standard MIDI file");
    const std::uint32_t header_length = big_endian(file, 4, 4);
    if (header_length < 6 || header_length > file.size() - 8)
        fail("header length " + std::to_string(header_length) + " is out of range: at least 6, within the file");
    const std::uint32_t format = big_endian(file, 8, 2);
    const std::uint32_t tracks = big_endian(file, 10, 2);
    const std::uint32_t division = big_endian(file, 12, 2);
    if (format == 2) fail("format 2 (independent sequences) is not supported: save it as format 0 or 1");
    if (format > 2) fail("format " + std::to_string(format) + " is out of range: 0 or 1");
    if (tracks == 0) fail("the header declares no track");
    if (format == 0 && tracks != 1) fail("format 0 holds one track; the header declares " + std::to_string(tracks));
    if (division & 0x8000) fail("uses SMPTE time (frames per second): only ticks per quarter note are supported");
    if (division == 0) fail("0 ticks per quarter note");

    std::vector<unsigned char> out = {'M', 'T', 'h', 'd', 0, 0, 0, 6, 0, 1};
    put_big_endian(out, tracks, 2);
    put_big_endian(out, division, 2);
    std::size_t at = 8 + header_length;
    for (std::uint32_t found = 0; found < tracks;) {
        if (file.size() - at < 8)
            fail("the header declares " + std::to_string(tracks) + " tracks but the file ends after " +
                 std::to_string(found) + " (byte " + std::to_string(at) + ")");
        const std::uint32_t length = big_endian(file, at + 4, 4);
        const bool track = file.substr(at, 4) == "MTrk";
        const std::string where = track ? "track " + std::to_string(found + 1) : "a chunk";
        if (length > file.size() - at - 8)
            fail(where + " at byte " + std::to_string(at) + " claims " + std::to_string(length) + " bytes; " +
                 std::to_string(file.size() - at - 8) + " are left in the file");
        if (track) {  // chunks of other kinds are skipped, as the standard asks
            const std::vector<unsigned char> events =
                TrackReader(file, at + 8, at + 8 + length, source + ": " + where).read();
            out.insert(out.end(), {'M', 'T', 'r', 'k'});
            put_big_endian(out, static_cast<std::uint32_t>(events.size()), 4);
            out.insert(out.end(), events.begin(), events.end());
            ++found;
        }
        at += 8 + length;
    }
    return out;
}

struct SmfDelete {
    void operator()(smf_t* smf) const { smf_delete(smf); }
};

}  // namespace

Score parse_midi(std::string_view bytes, const std::string& source_name, int open_note, int max_fret) {
    const std::string source = "--midi " + source_name;
    const std::vector<unsigned char> checked = checked_copy(bytes, source);
    const std::unique_ptr<smf_t, SmfDelete> smf(smf_load_from_memory(checked.data(), static_cast<int>(checked.size())));
    if (smf == nullptr) throw InputError(source + ": libsmf could not read it");
    smf_rewind(smf.get());  // every track from its first event: events come in time order
    Score p;
    std::map<int, std::pair<double, double>> sounding;  // note and channel -> (start, velocity)
    long skipped = 0;
    double end_s = 0.0;
    const auto finish = [&](int key, double start, double velocity, double now) {
        const int fret = (key & 0x7F) - open_note;
        if (fret < 0 || fret > max_fret) {
            ++skipped;
            return;
        }
        ScoreNote note;
        note.time_s = start;
        note.duration_s = now - start;
        note.fret = fret;
        note.velocity = velocity;
        p.notes.push_back(note);
    };
    smf_event_t* event = nullptr;
    while ((event = smf_get_next_event(smf.get())) != nullptr) {
        const double now = event->time_seconds;
        end_s = std::max(end_s, now);
        if (smf_event_is_metadata(event) || event->midi_buffer_length < 3) continue;
        const int status = event->midi_buffer[0] & 0xF0;
        const int key = event->midi_buffer[1] | ((event->midi_buffer[0] & 0x0F) << 8);  // note and channel
        const int velocity = event->midi_buffer[2];
        const auto it = sounding.find(key);
        if (it != sounding.end()) {  // a note-off, or the same note struck again: the last one ends
            finish(key, it->second.first, it->second.second, now);
            sounding.erase(it);
        }
        if (status == 0x90 && velocity > 0) sounding[key] = {now, velocity / 127.0};
    }
    for (const auto& [key, on] : sounding) finish(key, on.first, on.second, end_s);
    if (!sounding.empty())
        p.warnings.push_back(std::to_string(sounding.size()) +
                             " MIDI notes have no note-off: they end with the file, at its End of Track");
    if (skipped > 0)
        p.warnings.push_back(std::to_string(skipped) + " MIDI notes outside the string's range (MIDI " +
                             std::to_string(open_note) + " to " + std::to_string(open_note + max_fret) + ") skipped");
    if (p.notes.empty()) throw InputError(source + " holds no note the string can play");
    std::stable_sort(p.notes.begin(), p.notes.end(), [](const auto& a, const auto& b) { return a.time_s < b.time_s; });
    check_score_length(p, source);
    return p;
}

Score load_midi(const std::filesystem::path& path, int open_note, int max_fret) {
    // The checks of every file fretbuzz reads (regular, size first); the bytes come back as they are.
    return parse_midi(read_text_file(path, "--midi", kMaxMidiFileBytes), path.string(), open_note, max_fret);
}

}  // namespace fretbuzz
