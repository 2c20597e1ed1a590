#include "fretbuzz/setup/BuzzMap.hpp"

#include <algorithm>
#include <array>
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
#include "fretbuzz/SubnormalFlush.hpp"

namespace fretbuzz {

namespace {

constexpr double kQuietest = -std::numeric_limits<double>::infinity();

// The stiffness check's factors of each string's bending stiffness, and how the column names them.
constexpr std::array kStiffness{0.5, 1.5};
constexpr std::array<const char*, 2> kStiffnessNames{"0.5", "1.5"};

// The median of some values (the mean of the middle two of an even count); not empty.
double median(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    const std::size_t half = values.size() / 2;
    return values.size() % 2 ? values[half] : 0.5 * (values[half - 1] + values[half]);
}

}  // namespace

std::string note_audio_name(const std::string& string_name, std::size_t fret, const std::string& attack) {
    std::string label;
    for (char ch : attack) label += (std::isalnum(static_cast<unsigned char>(ch)) || ch == '.') ? ch : '_';
    std::string name = "note-" + string_name + (fret < 10 ? "-0" : "-");
    name += std::to_string(fret);
    return name + "-" + label + ".wav";
}

NoteVerdict summarise(const AttackJudgement& j, double audible_db) {
    NoteVerdict v;
    v.status = j.status;
    // The attack itself (member 0) could not be played: neither can the note.
    if (j.verdict.empty()) {
        if (v.status == "ok") v.status = "not played";
        return v;
    }
    v.verdict = j.verdict;
    std::vector<double> levels, touches;
    std::map<int, std::size_t> audible_frets, touching_frets;
    // j.plucks holds the ensemble in order, those not played included: its index is the member.
    const bool clean = j.verdict == "clean";
    double deciding = kQuietest;
    bool decided = false;
    for (std::size_t member = 0; member < j.plucks.size(); ++member) {
        const PluckOutcome& p = j.plucks[member];
        if (!p.error.empty()) continue;
        const double heard_db = p.touched && !std::isnan(p.buzz_db) ? p.buzz_db : kQuietest;
        const bool buzzes = heard_to_buzz(p, audible_db);
        if ((!decided || heard_db > deciding) && !(clean && buzzes)) {
            deciding = heard_db;
            decided = true;
            v.deciding_pluck = member;
        }
        v.pluck_db.push_back(p.buzz_db);
        v.pluck_fret.push_back(p.touched ? p.buzz_fret : kNoFret);
        v.pluck_touch_s.push_back(p.touched ? p.first_contact_s : NoteVerdict::nan);
        if (p.touched && std::isfinite(p.first_contact_s)) touches.push_back(p.first_contact_s);
        levels.push_back(heard_db);
        if (p.touched) ++touching_frets[p.buzz_fret];
        if (buzzes) ++audible_frets[p.buzz_fret];
    }
    v.plucks = j.counted;
    v.buzz_fraction = static_cast<double>(j.buzzing) / static_cast<double>(std::max<std::size_t>(j.counted, 1));
    v.buzz_fraction_low = j.interval.low;
    v.buzz_fraction_high = j.interval.high;
    v.touch_fraction = static_cast<double>(j.touching) / static_cast<double>(std::max<std::size_t>(j.counted, 1));
    const double level = levels.empty() ? kQuietest : median(levels);
    v.buzz_db = level > kQuietest ? level : NoteVerdict::nan;
    if (!touches.empty()) v.first_touch_s = median(touches);
    const auto& frets = audible_frets.empty() ? touching_frets : audible_frets;
    std::size_t most = 0;
    for (const auto& [fret, count] : frets)
        if (count > most) {
            most = count;
            v.buzz_fret = fret;
        }
    v.clean_up_to = j.clean_up_to;
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
    if (!request.notes.empty()) {
        for (const MapNote& n : request.notes)
            if (n.string >= instrument.strings.size() || n.fret < capo || n.fret > last)
                throw InputError(out_of_range_message("note (string " + std::to_string(n.string + 1) + ", fret)",
                                                      static_cast<double>(n.fret),
                                                      "must be a fret from " + std::to_string(capo) + " to " +
                                                          std::to_string(last) + " of one of the " +
                                                          std::to_string(instrument.strings.size()) + " strings"));
        return request.notes;
    }
    // A string or fret named twice is one note: each is played once.
    const auto once = [](std::vector<std::size_t>& v) {
        std::vector<std::size_t> kept;
        for (std::size_t x : v)
            if (std::find(kept.begin(), kept.end(), x) == kept.end()) kept.push_back(x);
        v = std::move(kept);
    };
    once(strings);
    once(frets);
    std::vector<MapNote> notes;
    for (std::size_t s : strings)
        for (std::size_t k : frets) notes.push_back({s, k});
    return notes;
}

namespace {

// The instrument with one string's bending stiffness scaled (the stiffness check's replays).
Instrument with_stiffness(const Instrument& instrument, std::size_t string, double factor) {
    Instrument changed = instrument;
    changed.strings[string].bending_stiffness *= factor;
    return changed;
}

}  // namespace

BuzzMapResult play_map(const Instrument& instrument, const MapRequest& request) {
    const std::vector<MapNote> notes = map_notes(instrument, request);
    const auto start = std::chrono::steady_clock::now();
    if (!request.audio_dir.empty()) std::filesystem::create_directories(request.audio_dir);
    // Per string: the instrument as it is, then (stiffness check) with the stiffness scaled.
    std::vector<std::vector<Instrument>> variants(instrument.strings.size());
    std::vector<std::vector<std::unique_ptr<NoteMaker>>> makers(instrument.strings.size());
    for (const MapNote& n : notes) {
        if (!makers[n.string].empty()) continue;
        variants[n.string].push_back(instrument);
        if (request.stiffness_check)
            for (double factor : kStiffness) variants[n.string].push_back(with_stiffness(instrument, n.string, factor));
        for (const Instrument& v : variants[n.string]) makers[n.string].push_back(std::make_unique<NoteMaker>(v, n.string));
    }
    const std::size_t attacks = request.attacks.size();
    const BenchSettings& bench = instrument.bench;

    BuzzMapResult result;
    result.notes.resize(notes.size() * attacks);
    std::mutex mutex;  // guards the result's counters and the callbacks
    std::size_t done = 0;
    const auto clearance_of = [&](const MapNote& n) {
        const StringNeck& neck = makers[n.string].front()->neck();
        double clearance = NoteVerdict::nan;
        for (std::size_t f = n.fret + 1; f <= neck.fret_count(); ++f)
            clearance = std::isnan(clearance) ? neck.clearance(n.fret, f) : std::min(clearance, neck.clearance(n.fret, f));
        return clearance;
    };
    const auto report = [&](std::size_t i, std::vector<NoteVerdict> verdicts) {  // with the mutex held
        const MapNote& n = notes[i];
        for (std::size_t a = 0; a < attacks; ++a) {
            NoteVerdict& v = verdicts[a];
            const Attack& attack = request.attacks[a];
            v.string = n.string;
            v.string_name = instrument.strings[n.string].name;
            v.fret = n.fret;
            v.strength = attack.label;
            v.unit = attack.unit();
            v.clean_up_to_value = v.clean_up_to * attack.shown_size();
            v.clearance_m = clearance_of(n);
            result.notes[i * attacks + a] = v;
            ++done;
            if (request.on_note) request.on_note(result.notes[i * attacks + a], done, result.notes.size());
            if (request.stop_when && request.stop_when(result.notes[i * attacks + a])) result.stopped_early = true;
        }
    };
    // Frets out: reported before anything is played.
    std::vector<std::size_t> playable;
    {
        std::lock_guard lock(mutex);
        for (std::size_t i = 0; i < notes.size(); ++i) {
            const MapNote& n = notes[i];
            if (const auto choke = makers[n.string].front()->neck().rests_on(n.fret)) {
                std::vector<NoteVerdict> verdicts(attacks);
                for (NoteVerdict& v : verdicts) {
                    v.status = "frets out";
                    v.verdict = "buzzes";
                    v.buzz_fraction = v.touch_fraction = v.buzz_fraction_low = v.buzz_fraction_high = 1.0;
                    v.buzz_fret = static_cast<int>(*choke);
                    v.clean_up_to = 0.0;
                }
                report(i, std::move(verdicts));
            } else {
                playable.push_back(i);
            }
        }
    }

    const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
    result.jobs = static_cast<unsigned>(
        std::max<std::size_t>(1, std::min<std::size_t>(playable.size(), request.jobs ? request.jobs : hardware)));
    std::atomic<std::size_t> next{0};
    std::exception_ptr failure;
    const auto worker = [&] {
        const SubnormalFlush flushed;  // each note's run and its listening, on this worker
        for (std::size_t t = next++; t < playable.size(); t = next++) {
            try {
                {
                    std::lock_guard lock(mutex);
                    if (!result.stopped_early && request.stop && request.stop()) result.stopped_early = true;
                    if (result.stopped_early) break;
                }
                throw_if_stopped();
                const std::size_t i = playable[t];
                const MapNote& n = notes[i];
                JudgeOptions options;
                options.finger = request.finger;
                options.clean_up_to = request.clean_up_to;
                options.sound_s = request.sound_s;
                if (!request.audio_dir.empty())
                    for (const Attack& a : request.attacks)
                        options.wavs.push_back(request.audio_dir /
                                               note_audio_name(instrument.strings[n.string].name, n.fret, a.label));
                NoteJudge judge(variants[n.string].front(), *makers[n.string].front(), n.fret, options);
                const std::vector<AttackJudgement> judgements = judge.judge(request.attacks);
                std::vector<NoteVerdict> verdicts;
                for (std::size_t a = 0; a < attacks; ++a) {
                    verdicts.push_back(summarise(judgements[a], bench.audible_db));
                    if (!options.wavs.empty() && verdicts.back().status == "ok")
                        verdicts.back().audio = options.wavs[a].filename().string();
                }
                std::size_t simulated = judge.plucks_simulated(), clear = judge.plucks_clear();
                // The stiffness check: the same plucks on the string made softer and stiffer.
                if (request.stiffness_check) {
                    for (NoteVerdict& v : verdicts) v.stiffness_sensitive = v.verdict.empty() ? "" : "no";
                    JudgeOptions replay = options;
                    replay.clean_up_to = false;
                    replay.wavs.clear();
                    std::vector<std::string> changed(attacks);
                    for (std::size_t k = 0; k < kStiffness.size(); ++k) {
                        NoteJudge other(variants[n.string][k + 1], *makers[n.string][k + 1], n.fret, replay);
                        const std::vector<AttackJudgement> again = other.judge(request.attacks);
                        for (std::size_t a = 0; a < attacks; ++a)
                            if (!verdicts[a].verdict.empty() && again[a].verdict != verdicts[a].verdict)
                                changed[a] += std::string(changed[a].empty() ? "" : ",") + kStiffnessNames[k];
                        simulated += other.plucks_simulated();
                        clear += other.plucks_clear();
                    }
                    for (std::size_t a = 0; a < attacks; ++a)
                        if (!changed[a].empty()) verdicts[a].stiffness_sensitive = changed[a];
                }
                std::lock_guard lock(mutex);
                result.plucks_simulated += simulated;
                result.plucks_clear += clear;
                report(i, std::move(verdicts));
            } catch (...) {
                std::lock_guard lock(mutex);
                if (!failure) failure = std::current_exception();
                next = playable.size();
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
