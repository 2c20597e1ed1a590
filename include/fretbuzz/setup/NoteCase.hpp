#pragma once
// The Case of one note of one string of an instrument, played one way.
//  - The stand-in (default): the note stopped at fret k is the string from fret k's top to
//    the saddle, over the frets beyond (the finger and the string behind the fret are left
//    out). Its string (length, modes) comes from stopped_string(), the string held on the
//    fret; or, with BenchSettings::pinned_stops, from the string's own frequency and damping
//    models at the stopped length (the string pinned at the fret, as the case-based set-up
//    study of the bass-neck case computed it). Its obstacle is the neck
//    under it as StringNeck computes it, every fret top exact; its pluck is the attack at the
//    same distance from the bridge as on the open string. The last fret is played too: past
//    it lie only the end of the board and the body.
//  - The finger model (--finger): the whole string resting on fret k, a finger pressing it
//    just behind the fret (the case files' `fret = k` finger) and, once it has settled, a
//    pick pulling the string away from the neck over whole periods of the note and letting go.
// Every note shares the open string's grid step unless the sampling rate calls for fewer
// modes: every mode stays below fs / 2. Its frets act at their exact positions (exact points,
// each over one grid step of string, as a case file's crowns of zero width); the board is
// on the grid.
#include <cstddef>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/input/Instrument.hpp"
#include "fretbuzz/setup/Attack.hpp"
#include "fretbuzz/setup/StringNeck.hpp"

namespace fretbuzz {

// Which polarisations a stand-in note carries. The frets push along z only and friction only
// drags y, so z (what a pickup senses) is the same with or without y: the bench's ensembles
// run z alone; a note played for listening and drawing runs both.
enum class Polarisations { z_only, both };

class NoteMaker {
public:
    NoteMaker(const Instrument& instrument, std::size_t string);

    const StringNeck& neck() const { return neck_; }
    const Case& open_string() const { return open_; }
    std::size_t string_index() const { return string_; }
    // The lowest partial of the stopped note (Hz): its fundamental.
    double fundamental_hz(std::size_t fret) const;

    // Why the note cannot be played this way (the pluck would fall behind the fret, or off
    // the string), or nothing.
    std::optional<std::string> unplayable(std::size_t fret, const Attack& attack, const PluckVariation& pluck,
                                          bool finger) const;
    Case stand_in(std::size_t fret, const Attack& attack, const PluckVariation& pluck,
                  Polarisations polarisations = Polarisations::z_only) const;
    // The stand-in note of a fret before it is plucked: its string and obstacle, built once
    // (the held string's modes cost tens of ms) and shared by every pluck of the note (threads too).
    const Case& stopped(std::size_t fret) const;
    Case fingered(std::size_t fret, const Attack& attack, const PluckVariation& pluck) const;
    // Where the frets the note can buzz against lie on its string (m from the note's own nut):
    // the frets past the stop, numbered as on the neck (fret_numbers).
    std::vector<double> fret_positions(std::size_t fret, bool finger) const;
    std::vector<std::size_t> fret_numbers(std::size_t fret) const;

private:
    // Each partial of a stopped note detuned at random by the bench's partial scatter (none by default).
    void scatter(ModeTable& modes, std::size_t fret) const;
    // The string's own modes at a vibrating length: stiff-string frequencies and the damping law.
    ModeTable string_modes(double length, std::size_t modes) const;
    double pluck_position(double sounding, const Attack& attack, const PluckVariation& pluck) const;
    void excite(Case& c, const Attack& attack, const PluckVariation& pluck, Polarisations polarisations) const;

    std::size_t string_;
    StringNeck neck_;
    Case open_;
    Case bare_;  // the open string with nothing to touch: what stopped_string shortens
    mutable std::vector<std::unique_ptr<Case>> stopped_;
    mutable std::vector<std::once_flag> once_;
    double observe_from_bridge_m_;
    double grid_step_m_;
    bool pinned_;
    double bending_stiffness_, eta0_, eta2_;
    double fret_friction_;
    double thumb_mass_, thumb_stiffness_, thumb_loss_;
    double scatter_cents_;         // BenchSettings::partial_scatter_cents
    unsigned long long seed_;
};

// The z share of an attack's release (or a thumb's speed) for a member of its ensemble: the
// size times the sine of its direction toward the board, negative toward the board.
double z_share(const Attack& attack, const PluckVariation& pluck);

// True when no point of the string can reach the obstacle, ever: every mode's amplitude
// (its largest displacement under its damping) summed with |phi_j(x_i)| stays below the
// clearance at every grid point and every exact point. Then the note is free motion and
// touches nothing.
bool never_touches(const Case& c);
// The factor by which the case's initial state can be scaled with never_touches() still
// true (infinity when it never can touch; 0 when no bound holds: a finger or thumb on it, or
// an overdamped mode). The free motion is linear in its initial state, so a pluck scaled by
// less than this touches nothing.
double touch_free_scale(const Case& c);

// The string's motion without any obstacle at x, in closed form: each mode a damped
// oscillator q_j(t) = e^(-sigma_j t) (q_j(0) cos(w_j t) + (sigma_j q_j(0) + v_j(0)) / w_j
// sin(w_j t)), w_j = sqrt(omega_j^2 - sigma_j^2): what the scheme computes where nothing
// touches (its free update is exact at any time step), sampled every `interval_s` from t = 0.
// Modes whose share is below 1e-13 of the whole are left out.
std::vector<double> free_motion_at(const Case& c, double x, double interval_s, std::size_t samples);

}  // namespace fretbuzz
