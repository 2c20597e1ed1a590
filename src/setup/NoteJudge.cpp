#include "fretbuzz/setup/NoteJudge.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace fretbuzz {

ShareInterval share_interval(std::size_t hits, std::size_t count) {
    const double n = static_cast<double>(count);
    const double p = static_cast<double>(hits) / n;
    const double z2 = kIntervalZ * kIntervalZ;
    const double centre = (p + z2 / (2.0 * n)) / (1.0 + z2 / n);
    const double half = kIntervalZ * std::sqrt(p * (1.0 - p) / n + z2 / (4.0 * n * n)) / (1.0 + z2 / n);
    return {std::max(0.0, centre - half), std::min(1.0, centre + half)};
}

std::string share_verdict(const ShareInterval& i) {
    if (i.high < kBuzzingShare) return "clean";
    if (i.low > kBuzzingShare) return "buzzes";
    return "marginal";
}

std::size_t plucks_for_clean() {
    std::size_t n = 1;
    while (share_interval(0, n).high >= kBuzzingShare) ++n;
    return n;
}

NoteJudge::NoteJudge(const Instrument& instrument, const NoteMaker& maker, std::size_t fret, const JudgeOptions& options)
    : instrument_(instrument),
      maker_(maker),
      fret_(fret),
      options_(options),
      members_(ensemble(instrument.attack, maker.string_index(), fret, std::max<std::size_t>(instrument.attack.ensemble, 1))),
      player_(maker, fret, options.finger, listening_settings(instrument.bench)) {}

bool NoteJudge::buzzes(const PluckOutcome& o) const {
    return heard_to_buzz(o, instrument_.bench.audible_db);
}

const PluckOutcome& NoteJudge::pluck(const Attack& attack, double size, std::size_t member) {
    for (const Played& p : played_)
        if (p.gesture == attack.gesture && p.member == member && p.size == size) return p.outcome;
    PluckOutcome o = player_.play(attack, size, member, members_[member]);
    if (o.error.empty()) ++(o.simulated ? simulated_ : clear_);
    played_.push_back({attack.gesture, member, size, std::move(o)});
    return played_.back().outcome;
}

AttackJudgement NoteJudge::verdict(const Attack& attack, std::size_t index) {
    AttackJudgement j;
    // Member 0 is the attack itself; its sound is the note's.
    if (index < options_.wavs.size() && !options_.wavs[index].empty()) {
        PluckOptions with_sound;
        with_sound.wav = options_.wavs[index];
        with_sound.sound_s = options_.sound_s;
        PluckOutcome o = player_.play(attack, attack.size, 0, members_[0], with_sound);
        if (o.error.empty()) ++(o.simulated ? simulated_ : clear_);
        played_.push_back({attack.gesture, 0, attack.size, std::move(o)});
    }
    const PluckOutcome& first = pluck(attack, attack.size, 0);
    if (!first.error.empty()) {
        j.status = first.error;
        j.plucks.push_back(first);
        return j;
    }
    const std::size_t most = members_.size();
    std::size_t member = 0, target = std::min(kFirstPlucks, most);
    while (true) {
        while (j.counted < target && member < most) {
            const PluckOutcome& o = pluck(attack, attack.size, member++);
            j.plucks.push_back(o);
            if (!o.error.empty()) {  // a jittered pluck behind the fret is left out; a failed run is reported
                if (o.error.starts_with("failed")) j.status = o.error;
                continue;
            }
            ++j.counted;
            j.touching += o.touched ? 1 : 0;
            j.buzzing += buzzes(o) ? 1 : 0;
        }
        j.interval = share_interval(j.buzzing, std::max<std::size_t>(j.counted, 1));
        const bool decided = share_verdict(j.interval) != "marginal";
        const bool narrow = j.interval.high - j.interval.low <= 2.0 * kShareHalfWidth;
        if (member >= most || (decided && narrow)) break;
        target = j.counted + kMorePlucks;
    }
    j.verdict = share_verdict(j.interval);
    return j;
}

double NoteJudge::clean_size(const Attack& attack, double cap) {
    // The members a clean verdict rests on: the first plucks_for_clean() that can be played.
    const std::size_t needed = plucks_for_clean();
    struct Candidate {
        std::size_t member;
        double touch_free;  // below this size it touches nothing
    };
    std::vector<Candidate> candidates;
    for (std::size_t m = 0; m < members_.size() && candidates.size() < needed; ++m)
        if (!maker_.unplayable(fret_, attack, members_[m], options_.finger))
            candidates.push_back({m, player_.touch_free_size(attack, members_[m])});
    std::sort(candidates.begin(), candidates.end(),
              [](const Candidate& a, const Candidate& b) { return a.touch_free < b.touch_free; });
    // What the note has played already: each member's smallest buzzing and largest clean size.
    const auto known = [&](std::size_t member, bool buzzing) {
        double best = buzzing ? std::numeric_limits<double>::infinity() : 0.0;
        for (const Played& p : played_)
            if (p.gesture == attack.gesture && p.member == member && p.outcome.error.empty() && buzzes(p.outcome) == buzzing)
                best = buzzing ? std::min(best, p.size) : std::max(best, p.size);
        return best;
    };
    double best = cap;  // every candidate is clean up to here
    bool bounded = false;
    for (const Candidate& c : candidates) best = std::min(best, known(c.member, true));
    bounded = best < cap;
    for (const Candidate& c : candidates) {
        if (c.touch_free >= best) break;  // sorted: none of the rest can touch below it
        double high = known(c.member, true);
        if (high > best) {
            if (known(c.member, false) >= best) continue;
            if (!buzzes(pluck(attack, best, c.member))) continue;
            high = best;
        }
        double low = std::max({c.touch_free, known(c.member, false), cap * 1e-3});
        if (low >= high) low = high * (1.0 - kCleanUpToTolerance);
        // Down until a size it stays clean at (the touch-free size always is).
        while (buzzes(pluck(attack, low, c.member))) {
            high = low;
            if (low <= std::max(c.touch_free, cap * 1e-3)) break;
            low = std::max({c.touch_free, cap * 1e-3, low * 0.25});
        }
        if (high == low) {
            best = low;
            bounded = true;
            continue;
        }
        while (high > low * (1.0 + kCleanUpToTolerance)) {
            const double mid = std::sqrt(low * high);
            (buzzes(pluck(attack, mid, c.member)) ? high : low) = mid;
        }
        best = std::min(best, low);
        bounded = true;
    }
    return bounded ? best : std::numeric_limits<double>::infinity();
}

std::vector<AttackJudgement> NoteJudge::judge(std::span<const Attack> attacks) {
    std::vector<AttackJudgement> out;
    for (std::size_t a = 0; a < attacks.size(); ++a) out.push_back(verdict(attacks[a], a));
    if (!options_.clean_up_to) return out;
    for (const Gesture gesture : {Gesture::finger, Gesture::pick, Gesture::pop, Gesture::slap}) {
        double largest = 0.0;
        const Attack* any = nullptr;
        for (std::size_t a = 0; a < attacks.size(); ++a)
            if (attacks[a].gesture == gesture && out[a].status == "ok") {
                largest = std::max(largest, attacks[a].size);
                any = &attacks[a];
            }
        if (!any) continue;
        const double size = clean_size(*any, kCleanUpToCap * largest);
        for (std::size_t a = 0; a < attacks.size(); ++a)
            if (attacks[a].gesture == gesture && out[a].status == "ok") out[a].clean_up_to = size / attacks[a].size;
    }
    return out;
}

}  // namespace fretbuzz
