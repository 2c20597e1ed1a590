#include "fretbuzz/setup/BuzzMap.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <exception>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "fretbuzz/Error.hpp"

namespace fretbuzz {

namespace {

constexpr double kQuietest = -std::numeric_limits<double>::infinity();

}  // namespace

std::string note_audio_name(const std::string& string_name, std::size_t fret, const std::string& attack) {
    std::string label;
    for (char ch : attack) label += (std::isalnum(static_cast<unsigned char>(ch)) || ch == '.') ? ch : '_';
    std::string name = "note-" + string_name + (fret < 10 ? "-0" : "-");
    name += std::to_string(fret);
    return name + "-" + label + ".wav";
}

NoteVerdict judge(std::vector<PluckOutcome> plucks, double audible_db) {
    NoteVerdict v;
    // The attack itself (member 0) could not be played: neither can the note.
    if (plucks.empty() || !plucks.front().error.empty()) {
        v.status = plucks.empty() ? "not played" : plucks.front().error;
        return v;
    }
    std::vector<double> levels;
    std::map<int, std::size_t> audible_frets, touching_frets;
    std::size_t audible = 0, touching = 0;
    for (const PluckOutcome& p : plucks) {
        if (!p.error.empty()) {  // a jittered pluck behind the fret is left out; a failed run is reported
            if (p.error.starts_with("failed")) v.status = p.error;
            continue;
        }
        ++v.plucks;
        v.pluck_db.push_back(p.buzz_db);
        v.pluck_fret.push_back(p.touched ? p.buzz_fret : kNoFret);
        levels.push_back(std::isfinite(p.buzz_db) ? p.buzz_db : kQuietest);
        if (p.touched) {
            ++touching;
            ++touching_frets[p.buzz_fret];
        }
        if (p.touched && p.buzz_db >= audible_db) {
            ++audible;
            ++audible_frets[p.buzz_fret];
        }
    }
    v.buzz_fraction = static_cast<double>(audible) / static_cast<double>(v.plucks);
    v.touch_fraction = static_cast<double>(touching) / static_cast<double>(v.plucks);
    std::sort(levels.begin(), levels.end());
    const std::size_t half = levels.size() / 2;
    const double median = levels.size() % 2 ? levels[half] : 0.5 * (levels[half - 1] + levels[half]);
    v.buzz_db = std::isfinite(median) ? median : NoteVerdict::nan;
    const auto& frets = audible ? audible_frets : touching_frets;
    std::size_t most = 0;
    for (const auto& [fret, count] : frets)
        if (count > most) {
            most = count;
            v.buzz_fret = fret;
        }
    return v;
}

std::vector<MapNote> map_notes(const Instrument& instrument, const MapRequest& request) {
    std::vector<std::size_t> strings = request.strings;
    if (strings.empty())
        for (std::size_t s = 0; s < instrument.strings.size(); ++s) strings.push_back(s);
    const std::size_t last = instrument.neck.fret_count;
    // A capo stops every string at its fret: the notes below it are not played, the capo's
    // own fret is the open string.
    const std::size_t capo = instrument.neck.capo;
    std::vector<std::size_t> frets = request.frets;
    if (frets.empty())
        for (std::size_t k = capo; k <= last; ++k) frets.push_back(k);
    for (std::size_t k : frets)
        if (k < capo)
            throw InputError(out_of_range_message("--frets", static_cast<double>(k),
                                                  "fret " + std::to_string(k) + " lies below the capo (neck.capo = " +
                                                      std::to_string(capo) + "): frets are " + std::to_string(capo) +
                                                      " (the capo) to " + std::to_string(last)));
    for (std::size_t s : strings)
        if (s >= instrument.strings.size())
            throw InputError(out_of_range_message("--strings (string number)", static_cast<double>(s + 1),
                                                  "must be in [1, " + std::to_string(instrument.strings.size()) + "]"));
    for (std::size_t k : frets)
        if (k > last)
            throw InputError(out_of_range_message("--frets", static_cast<double>(k),
                                                  "fret " + std::to_string(k) + " does not exist: frets are 0 (open) to " +
                                                      std::to_string(last)));
    if (request.attacks.empty()) throw InputError("--strength: give at least one attack");
    std::vector<MapNote> notes;
    for (std::size_t s : strings)
        for (std::size_t k : frets) notes.push_back({s, k});
    return notes;
}

BuzzMapResult play_map(const Instrument& instrument, const MapRequest& request) {
    const std::vector<MapNote> notes = map_notes(instrument, request);
    const auto start = std::chrono::steady_clock::now();
    if (!request.audio_dir.empty()) std::filesystem::create_directories(request.audio_dir);
    std::vector<std::unique_ptr<NoteMaker>> makers(instrument.strings.size());
    for (const MapNote& n : notes)
        if (!makers[n.string]) makers[n.string] = std::make_unique<NoteMaker>(instrument, n.string);
    const std::size_t attacks = request.attacks.size();
    const BenchSettings& bench = instrument.bench;
    PluckRequest pluck_request;
    pluck_request.finger = request.finger;
    pluck_request.band_hz = bench.buzz_band_hz;

    // One task per member of each note's ensemble; a note's verdicts follow its last task.
    struct NoteWork {
        std::vector<PluckVariation> members;
        std::vector<std::vector<PluckOutcome>> outcomes;  // [member][attack]
        std::size_t left = 0;
        std::optional<std::size_t> choke;  // what the note rests on (0: the board or body)
    };
    std::vector<NoteWork> work(notes.size());
    // A note's string (the stand-in's held string) is built once, by a task of its own queued
    // one note ahead: while one thread plays a note's plucks, the other prepares the next note,
    // instead of waiting for it behind the first pluck that needs it.
    struct Task {
        std::size_t note, member;
        bool prepare = false;
    };
    std::vector<Task> tasks;
    std::vector<std::size_t> playable;
    for (std::size_t i = 0; i < notes.size(); ++i) {
        const MapNote& n = notes[i];
        NoteWork& w = work[i];
        w.choke = makers[n.string]->neck().rests_on(n.fret);
        w.members = ensemble(instrument.attack, n.string, n.fret);
        w.outcomes.resize(w.members.size());
        w.left = w.choke ? 0 : w.members.size();
        if (!w.choke) playable.push_back(i);
    }
    for (std::size_t p = 0; p < playable.size(); ++p) {
        if (!request.finger) {
            if (p == 0) tasks.push_back({playable[0], 0, true});
            if (p + 1 < playable.size()) tasks.push_back({playable[p + 1], 0, true});
        }
        for (std::size_t m = 0; m < work[playable[p]].members.size(); ++m) tasks.push_back({playable[p], m});
    }

    BuzzMapResult result;
    result.notes.resize(notes.size() * attacks);
    std::mutex mutex;  // guards the work records, the result's counters and the callback
    std::size_t done = 0;
    const auto finish_note = [&](std::size_t i) {  // with the mutex held
        const MapNote& n = notes[i];
        const StringNeck& neck = makers[n.string]->neck();
        double clearance = NoteVerdict::nan;
        for (std::size_t f = n.fret + 1; f <= neck.fret_count(); ++f)
            clearance = std::isnan(clearance) ? neck.clearance(n.fret, f) : std::min(clearance, neck.clearance(n.fret, f));
        for (std::size_t a = 0; a < attacks; ++a) {
            NoteVerdict v;
            if (work[i].choke) {
                v.status = "frets out";
                v.buzz_fraction = v.touch_fraction = 1.0;
                v.buzz_fret = static_cast<int>(*work[i].choke);
            } else {
                std::vector<PluckOutcome> plucks;
                for (auto& member : work[i].outcomes) plucks.push_back(std::move(member[a]));
                v = judge(std::move(plucks), bench.audible_db);
                if (!request.audio_dir.empty() && v.status == "ok")
                    v.audio = note_audio_name(instrument.strings[n.string].name, n.fret, request.attacks[a].label);
            }
            v.string = n.string;
            v.string_name = instrument.strings[n.string].name;
            v.fret = n.fret;
            v.strength = request.attacks[a].label;
            v.clearance_m = clearance;
            result.notes[i * attacks + a] = v;
            ++done;
            if (request.on_note) request.on_note(result.notes[i * attacks + a], done, result.notes.size());
            if (request.stop_when && request.stop_when(result.notes[i * attacks + a])) result.stopped_early = true;
        }
    };
    {
        std::lock_guard lock(mutex);
        for (std::size_t i = 0; i < notes.size(); ++i)
            if (work[i].choke) finish_note(i);
    }

    const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
    result.jobs = static_cast<unsigned>(
        std::max<std::size_t>(1, std::min<std::size_t>(tasks.size(), request.jobs ? request.jobs : hardware)));
    std::atomic<std::size_t> next{0};
    std::exception_ptr failure;
    const auto worker = [&] {
        for (std::size_t t = next++; t < tasks.size(); t = next++) {
            try {
                {
                    std::lock_guard lock(mutex);
                    if (!result.stopped_early && request.stop && request.stop()) result.stopped_early = true;
                    if (result.stopped_early) break;
                }
                throw_if_stopped();
                const Task& task = tasks[t];
                const MapNote& n = notes[task.note];
                if (task.prepare) {
                    makers[n.string]->stopped(n.fret);
                    continue;
                }
                std::vector<std::filesystem::path> wavs;
                if (task.member == 0 && !request.audio_dir.empty())
                    for (const Attack& a : request.attacks)
                        wavs.push_back(request.audio_dir /
                                       note_audio_name(instrument.strings[n.string].name, n.fret, a.label));
                std::vector<PluckOutcome> outcomes = play_plucks(*makers[n.string], n.fret, request.attacks,
                                                                 work[task.note].members[task.member], pluck_request, wavs);
                std::lock_guard lock(mutex);
                for (const PluckOutcome& o : outcomes) (o.simulated ? result.plucks_simulated : result.plucks_clear) += o.error.empty();
                work[task.note].outcomes[task.member] = std::move(outcomes);
                if (--work[task.note].left == 0) finish_note(task.note);
            } catch (...) {
                std::lock_guard lock(mutex);
                if (!failure) failure = std::current_exception();
                next = tasks.size();
            }
        }
    };
    {
        std::vector<std::jthread> workers;
        for (unsigned j = 0; j < result.jobs; ++j) workers.emplace_back(worker);
    }
    if (failure) std::rethrow_exception(failure);
    if (result.stopped_early)  // only the notes that finished
        std::erase_if(result.notes, [](const NoteVerdict& v) { return v.string_name.empty(); });
    result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

}  // namespace fretbuzz
