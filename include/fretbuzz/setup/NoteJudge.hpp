#pragma once
// The verdict on one note (string, fret) at each attack, from an ensemble of plucks grown
// until it is sure, and how hard the note can be played before it buzzes.
//  - A pluck buzzes when its contacts are heard (its level reaches BenchSettings::audible_db
//    above the masked threshold: NotePlayer, analysis/Listener).
//  - The note's buzz fraction is the share of its plucks that buzz, with its 90 % Wilson
//    score interval (E. B. Wilson, JASA 22, 1927; recommended for small samples by Brown, Cai
//    & DasGupta, Statistical Science 16(2), 2001). A note buzzes when more than one pluck in
//    ten does (kBuzzingShare): its verdict is "clean" when the whole interval lies below
//    0.1, "buzzes" when it lies above, "marginal" when it straddles 0.1.
//  - The ensemble starts at 10 plucks and grows by 5 until the verdict is decided and the
//    interval is narrower than +-0.15, or 40 plucks (AttackSettings::ensemble) are played.
//    A clean verdict so needs 25 plucks none of which buzzes; a note that buzzes in 14 % of
//    plucks is called clean in 2.3 % of ensembles (0.86^25).
//  - clean_up_to: the strongest attack of the same gesture, as a multiple of its size, at
//    which the note stays clean: the smallest size at which any of the 25 members a clean
//    verdict rests on buzzes, found per member by bisection on the size (to 1 %), the members
//    taken in the order of the size at which they could first touch a fret (a bound in
//    closed form: members that cannot touch below the best size so far are never played).
//    Plucks the note has already played are reused. Above kCleanUpToCap times the largest
//    attack of the gesture no search goes: clean_up_to is then infinity ("at least that").
#include <cstddef>
#include <deque>
#include <filesystem>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "fretbuzz/input/Instrument.hpp"
#include "fretbuzz/setup/Attack.hpp"
#include "fretbuzz/setup/NotePlayer.hpp"

namespace fretbuzz {

inline constexpr double kBuzzingShare = 0.1;
inline constexpr double kShareHalfWidth = 0.15;
inline constexpr double kIntervalZ = 1.6448536269514722;  // 90 %, two-sided
inline constexpr std::size_t kFirstPlucks = 10;
inline constexpr std::size_t kMorePlucks = 5;
inline constexpr double kCleanUpToCap = 3.0;
inline constexpr double kCleanUpToTolerance = 0.01;

struct ShareInterval {
    double low = 0.0, high = 1.0;
};
// The 90 % Wilson score interval of a share of `hits` in `count` (count > 0).
ShareInterval share_interval(std::size_t hits, std::size_t count);
// "clean", "buzzes" or "marginal" for that interval.
std::string share_verdict(const ShareInterval& interval);
// The plucks a clean verdict needs at the least: none of them buzzing (25).
std::size_t plucks_for_clean();

// One attack's outcome on a note.
struct AttackJudgement {
    std::vector<PluckOutcome> plucks;   // as played, in the ensemble's order (errors: not counted)
    std::string verdict;                // "clean", "marginal", "buzzes"; "" when the note cannot be played
    std::string status = "ok";          // "ok", "not played: ...", "failed: ..."
    std::size_t counted = 0, buzzing = 0, touching = 0;
    ShareInterval interval;
    double clean_up_to = std::numeric_limits<double>::quiet_NaN();  // multiple of the attack's size
};

struct JudgeOptions {
    bool finger = false;
    bool clean_up_to = true;
    std::vector<std::filesystem::path> wavs;  // per attack: member 0's sound (empty: none)
    double sound_s = 0.0;                      // its length (the note is judged on the bench's duration)
};

class NoteJudge {
public:
    NoteJudge(const Instrument& instrument, const NoteMaker& maker, std::size_t fret, const JudgeOptions& options);
    // Every attack's judgement (in the given order).
    std::vector<AttackJudgement> judge(std::span<const Attack> attacks);
    std::size_t plucks_simulated() const { return simulated_; }
    std::size_t plucks_clear() const { return clear_; }

private:
    struct Played {
        Gesture gesture;
        std::size_t member;
        double size;
        PluckOutcome outcome;
    };
    const PluckOutcome& pluck(const Attack& attack, double size, std::size_t member);
    bool buzzes(const PluckOutcome& o) const;
    AttackJudgement verdict(const Attack& attack, std::size_t index);
    // The largest size of `gesture` at which the first clean-verdict members all stay clean.
    double clean_size(const Attack& attack, double cap);

    const Instrument& instrument_;
    const NoteMaker& maker_;
    std::size_t fret_;
    JudgeOptions options_;
    std::vector<PluckVariation> members_;
    NotePlayer player_;
    std::deque<Played> played_;  // (references to its outcomes stay valid as it grows)
    std::size_t simulated_ = 0, clear_ = 0;
};

}  // namespace fretbuzz
