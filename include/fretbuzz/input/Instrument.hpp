#pragma once
// An instrument on the set-up bench as a luthier describes it: the neck (scale, frets,
// relief, radius), each string (pitch, tension, stiffness, where it lies over the frets),
// how it is played (the attacks) and how finely it is simulated. Values in SI units, as
// read from an instrument file (docs/instrument-format.md) by input/InstrumentFile; the
// geometry they imply (fret tops, the string line, the obstacle of every note) is
// computed by setup/StringNeck.
#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/model/ListeningRig.hpp"
#include "fretbuzz/geometry/NeckBeam.hpp"

namespace fretbuzz {

// The neck's relief (its bow under the strings' pull, set by the truss rod), as measured.
struct ReliefMeasure {
    enum class Form {
        straight,  // no relief
        gap,       // a feeler gauge's gap at `at_fret` under a string pressed at fret 1 and the last fret
        curve,     // depth below the straight line from the nut to the last fret, at points along the neck
    };
    Form form = Form::straight;
    double gap_m = 0.0;
    std::size_t at_fret = 8;
    std::vector<double> x_m;      // curve: from the nut along the string, increasing, strictly inside
    std::vector<double> depth_m;  // curve: below that line (+ down)
};

// Where one end of the open string lies. At the nut: the gap over fret 1 (what a luthier
// measures), or the height above the fret plane at x = 0. At the bridge: the gap over a
// given fret (the action, usually at fret 12), or the height above the fret plane extended
// to the bridge (the saddle). The fret plane is the straight line through the nut end of
// the fretboard's fret line and the last fret (relief is measured down from it).
struct StringEnd {
    // as_measured: where a measured neck profile puts it (the profile is taken under the open string).
    enum class Form { gap_over_fret, height, as_measured };
    Form form = Form::gap_over_fret;
    double value_m = 0.0;
    std::size_t fret = 1;  // gap_over_fret: which fret
};

struct InstrumentString {
    std::string name;             // unique within the instrument: "E", "A", ..., "e"
    double scale_length_m = 0.0;  // its vibrating length, nut to saddle
    double frequency_hz = 0.0;    // open pitch
    double tension_n = 0.0;
    double linear_density = 0.0;  // mu, kg/m
    double bending_stiffness = 0.0;  // EI, N m^2 (B = pi^2 EI / (T L^2))
    double gauge_m = 0.0;         // outer diameter (0: not given)
    std::string tension_source;   // where the tension comes from (the set, "given", "from mu")
    StringEnd nut;
    StringEnd bridge;
    // Where the file measures the action (Fender's basses: fret 17); the advice says its
    // answer there too. What-ifs that pin the ends keep it.
    std::size_t action_fret = 12;
    // A scan of this string's fret tops: fret -> height above the straight line through the
    // tops of fret 1 and the last fret (m; negative below). Replaces relief, radius and the
    // individual fret heights under this string.
    std::map<std::size_t, double> scan_m;
    // A measured neck profile under this string: heights (m, negative below) of the neck
    // below the open string at rest on a grid x_i from the nut, frets one grid point each
    // (as the paper's bass data). Replaces the neck's geometry under this string.
    std::vector<double> profile_x_m, profile_height_m;
    std::string profile_source;
    // The body's height above the fret plane under this string, once what-ifs have pinned the
    // string's ends (the body stays with the neck when the string moves); none: from body_depth_m.
    std::optional<double> body_height_m;
};

struct NeckDescription {
    std::size_t fret_count = 0;
    double fret_height_m = 0.0;                    // nominal crown height above the board
    std::map<std::size_t, double> fret_offset_m;   // individual frets: + proud of the fret line, - low
    ReliefMeasure relief;
    double truss_rod_bow_m = 0.0;                  // a bow added to the relief (what-ifs of the truss rod)
    // The neck as a beam under the strings' pull (geometry/NeckBeam.hpp), and the pull the
    // relief was measured under (the file's own strings; none: the relief does not follow the
    // pull). Strings pulling more or less than that bow the neck by the difference.
    NeckBeam beam;
    std::optional<double> relief_pull_n;
    std::optional<double> radius_m;                // fretboard radius at the nut (cylindrical unless the next is given)
    std::optional<double> radius_last_fret_m;      // compound (conical) board: the radius at the last fret
    std::size_t capo = 0;                          // a capo on this fret (0: none): the notes below it are not played
    double nut_width_m = 0.0;                      // centre to centre of the outer strings at the nut
    double bridge_spacing_m = 0.0;                 // the same at the bridge
    std::optional<std::size_t> perpendicular_fret;  // multiscale: the fret square to the neck
    double board_end_m = 0.0;                      // end of the fingerboard, from the nut along the string
    std::optional<double> body_depth_m;            // past the board: the body, this far below the open string at the board's end
};

// One way of playing the string (a gesture): where along it, over what width, in which direction.
struct GestureSettings {
    double from_bridge_m = 0.0;       // where, from the bridge
    double width_m = 0.0;             // fingertip, plectrum or thumb
    // Direction of the release from the board's plane toward the board, degrees: a finger
    // pluck pulled along the board and let go slightly toward it (> 0); a pop pulled straight
    // away from it (-90); a slap strikes straight toward it (90).
    double angle_deg = 0.0;
};

// How the strings are played, and where those defaults come from (cases/attacks/STYLE.toml,
// each value with its source; an instrument file's [attack] overrides any of them).
//  - finger plucks (soft, medium, hard): the string pulled by a fingertip and released from
//    rest, displaced by the amplitude along the gesture's direction (a rounded triangle the
//    width of the fingertip);
//  - a pick stroke: the same with a plectrum's narrow edge;
//  - a pop: pulled straight away from the board by a finger hooked under the string;
//  - a slap: the thumb, a mass, strikes the string toward the board at a speed and bounces off.
// Each note is played as an ensemble of such gestures: each member's place, direction and
// size uniform within +- the spreads around the attack's (member 0 is the attack itself).
struct AttackSettings {
    std::string style;                // "bass" or "guitar": whose defaults
    GestureSettings finger, pick, pop, slap;
    double soft_m = 0.0, medium_m = 0.0, hard_m = 0.0;  // finger plucks' amplitudes
    double pick_m = 0.0, pop_m = 0.0;
    double slap_m_per_s = 0.0;        // the thumb's speed toward the board
    double thumb_mass_kg = 0.0, thumb_stiffness = 0.0, thumb_loss = 0.0;
    double position_spread_m = 0.0;
    double angle_spread_deg = 0.0;
    double strength_spread = 0.0;     // relative
    // Each note is played until its verdict is sure, at most this many plucks; the same
    // instrument and seed give the same plucks on every machine.
    std::size_t ensemble = 40;
    unsigned long long seed = 1;
};

// How finely the notes are simulated and how buzz is judged.
struct BenchSettings {
    double sample_rate_hz = 0.0;
    double duration_s = 0.0;
    double grid_step_m = 0.0;          // dx of every note's grid (each fret acts over one dx of string)
    double output_rate_hz = 48000.0;   // rows of the observed signal
    double observe_from_bridge_m = 0.0;  // where the signal is taken (a bridge pickup)
    // What is heard (analysis/Listener.hpp): the clean note's loudest frame played back at this
    // level, and a pluck heard to buzz when its contacts rise this far above the masked threshold.
    double listening_level_db_spl = 85.0;
    double audible_db = 0.0;
    // What the listener hears the pickup through: the rig (cases/rigs/STYLE.toml's figures, the
    // file's [rig] over them) or, with listen = "pickup" (--listen pickup), its full range.
    // Each stopped note's partials detuned at random by this rms (cents; 0: the model's exact
    // frequencies): what keeps real strings from recombining their partials in phase as the
    // model does (the coherence study, docs/setup.md).
    double partial_scatter_cents = 0.0;
    bool listen_through_rig = true;
    RigSettings rig;
    double fret_friction = 0.0;        // Coulomb coefficient at the frets (the y polarisation's drag)
    double contact_stiffness = 1e13;   // K
    double contact_exponent = 1.5;     // alpha
    ContactLawKind contact_law = ContactLawKind::penalty;  // [contact] law, and its restitution
    double restitution = 0.0;
    double damping_eta0 = 0.0;         // sigma_j = eta0 + eta2 (j pi / L)^2
    double damping_eta2 = 0.0;
    // Stopped notes' modes: false, the string held on the fret (the library's stopped_string);
    // true, the string pinned at the fret (its own models at the stopped length).
    bool pinned_stops = false;
};

// The unit a luthier's file gives its gaps in (the strings' nut and action values), which the
// bench's advice answers in (mm beside): mm, 64ths of an inch ("5/64 in": an action gauge) or
// thousandths of an inch ("0.094 in": feeler gauges).
enum class ShopUnits { mm, sixty_fourths, thousandths };

// The unit a bare number stands for in a what-if on such a file: "mm", or "in" (64ths and
// thousandths are inches: a bare 0.012 is 0.012 in, a bare 3/32 is 3/32 in).
inline const char* written_length_unit(ShopUnits units) { return units == ShopUnits::mm ? "mm" : "in"; }

// How the bench listens, as the file's rig.listen, --listen and Python's listen name it: "rig"
// (true) or "pickup" (false); InputError naming `key` otherwise.
bool listens_through_rig(const std::string& word, const std::string& key);
// A partial scatter (BenchSettings::partial_scatter_cents), checked: InputError naming `key`
// unless in [0, kMostPartialScatterCents].
inline constexpr double kMostPartialScatterCents = 50.0;
double checked_partial_scatter(double cents, const std::string& key);

// The screws a set-up turns, where the file gives what a turn does (0: not given). A truss
// rod's turn is measured on the neck (its thread, the rod's curve and the wood decide it); a
// saddle's height screws raise it by their thread's pitch per turn.
struct Adjusters {
    double truss_rod_turn_m = 0.0;      // relief gap at the relief fret taken off per turn tightened
    double saddle_screw_pitch_m = 0.0;  // a saddle's rise per turn of its height screws (clockwise)
};

struct Instrument {
    std::string name;
    std::string description;
    std::string source_text;  // the instrument file it was read from
    NeckDescription neck;
    std::vector<InstrumentString> strings;  // in the file's order (low to high)
    AttackSettings attack;
    BenchSettings bench;
    Adjusters adjusters;
    std::vector<std::string> warnings;  // what reading it found doubtful but not wrong (e.g. a mass implausible for a gauge)
    ShopUnits units = ShopUnits::mm;    // as the first string's nut or action is written

    // The index of the string called `name`; InputError listing the names if none is.
    std::size_t string_index(const std::string& name) const;
};

}  // namespace fretbuzz
