#pragma once
// What the advice and the fret dress share (private to setup/):
//  - NoteTrials: the notes they play, kept with the geometry they were played on, so that no
//    search plays a note again where its outcome follows from the geometry: the same
//    geometry gives the same plucks and the same verdict; a note that passed stays passing
//    wherever every fret past its stop lies at least as far below its string (more clearance
//    everywhere: the string meets the frets no sooner, no harder), and one that failed keeps
//    failing wherever every fret lies at least as close. Each probe plays the rest, in the
//    order given, and stops at the first that fails.
//  - NoteForecast: the notes' clean_up_to in the map before any change, carried to another
//    geometry (PluckReach.hpp): where a search starts, and which notes a probe plays first.
#include <cstddef>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fretbuzz/setup/Advice.hpp"
#include "fretbuzz/setup/BuzzMap.hpp"
#include "fretbuzz/setup/StringNeck.hpp"
#include "fretbuzz/setup/WhatIf.hpp"

namespace fretbuzz {

class NoteTrials {
public:
    NoteTrials(const AdviceRequest& request, std::size_t* maps) : request_(request), maps_(maps) {}

    // Whether a verdict passes: clean, or marginal when marginal notes are tolerated.
    bool passes(const NoteVerdict& v) const;
    // Keeps a map's verdicts at the request's attack, played on `instrument`.
    void remember(const Instrument& instrument, const std::vector<NoteVerdict>& map);
    // The verdicts of `notes` on `instrument` (each recalled when it follows, else played),
    // in order, up to and including the first for which `bad` is true (then it stops). A
    // failure recalled from a closer geometry carries the verdict it was played with (the fret
    // it buzzed against there): recall_failures = false plays those again.
    std::vector<NoteVerdict> play(const Instrument& instrument, const std::vector<MapNote>& notes,
                                  const std::function<bool(const NoteVerdict&)>& bad, bool recall_failures = true);
    // Every verdict, none left out.
    std::vector<NoteVerdict> play_all(const Instrument& instrument, const std::vector<MapNote>& notes,
                                      bool recall_failures = true) {
        return play(instrument, notes, [](const NoteVerdict&) { return false; }, recall_failures);
    }
    // The first of `notes` that fails on `instrument`; none when all pass.
    std::optional<NoteVerdict> first_failure(const Instrument& instrument, const std::vector<MapNote>& notes);

private:
    struct Trial {
        std::size_t string, fret;
        std::vector<double> clearance;  // frets k+1 .. N under the note's string at rest
        bool passed;
        NoteVerdict verdict;
    };
    const Trial* recall(const MapNote& note, const std::vector<double>& clearance, bool failures) const;

    AdviceRequest request_;
    std::size_t* maps_;
    std::vector<Trial> trials_;
};

class NoteForecast {
public:
    NoteForecast(const Instrument& instrument, const std::vector<NoteVerdict>& map, const Attack& attack);
    bool usable() const { return !up_to_.empty(); }
    // The note's clean_up_to on a changed neck (`changed`: under the note's string); NaN: unknown.
    double up_to(const StringNeck& changed, std::size_t string, std::size_t fret) const;
    // Whether every note of `frets` on the string is predicted to pass (unknown ones do).
    bool passes(const StringNeck& changed, std::size_t string, const std::vector<std::size_t>& frets) const;
    // The notes in the order a probe plays them: those predicted nearest to buzzing (or unknown) first.
    std::vector<MapNote> ordered(const Instrument& changed, const std::vector<MapNote>& notes) const;

private:
    double pluck_from_bridge_m_;
    std::map<std::pair<std::size_t, std::size_t>, double> up_to_;
    std::map<std::size_t, StringNeck> necks_;
};

// The strings the advice answers for (all when none are named).
std::vector<std::size_t> wanted_strings(const Instrument& instrument, const AdviceRequest& request);
std::vector<MapNote> notes_of(const std::vector<std::size_t>& strings, const std::vector<std::size_t>& frets);
// "E 7"; "E fret 7: buzzes, 3/10 plucks buzz against fret 8".
std::string note_name(const NoteVerdict& v);
std::string failure_text(const NoteVerdict& v);
// The instrument after a change, or nothing when the change cannot be made (a string on a fret).
std::optional<Instrument> changed_or_none(const Instrument& instrument, const SetupChange& change);
// The smallest index in [low, high] for which `holds` is true, `holds` being monotone (false
// below some index, true from it on), by bisection, starting at `guess` and galloping out
// from it; high + 1 when it never holds.
long lowest_holding(long low, long high, const std::function<bool(long)>& holds, long guess = -1);

}  // namespace fretbuzz
