#pragma once
// Values with their units, as an instrument file and the bench's options give them:
// "2.4 mm", "5/64 in", "3/32 in", "1 3/16 in", "0.094 in", "12 thou", "34 in", "191.6 N", "43.1 lb", "98 Hz",
// "E1" (a note: equal temperament, A4 = 440 Hz), "1 MHz", "0.3 s". Every value is
// converted to SI units; docs/instrument-format.md lists the units of each kind.
#include <cstddef>
#include <string>
#include <string_view>

namespace fretbuzz {

enum class Quantity {
    length,             // m, cm, mm, in, thou (0.001 in); fractions of an inch in any denominator
    force,              // N, lb (pound-force)
    frequency,          // Hz, kHz, MHz, or a note name (E1, F#2, Bb3)
    linear_density,     // kg/m, g/m, lb/in (the unit weight of string makers' charts)
    bending_stiffness,  // N m^2
    velocity,           // m/s
    rate,               // 1/s
    diffusivity,        // m^2/s
    time,               // s, ms
    mass,               // kg, g
};

// The unit names accepted for a kind of quantity, for messages ("m, cm, mm or in").
std::string unit_names(Quantity kind);

// The value in SI units. InputError naming `key` if the text is no number followed by one of
// the kind's units (a bare number is refused: the unit must be said), or not finite.
double parse_quantity(std::string_view text, Quantity kind, const std::string& key);

// The same, but a bare number is taken in `default_unit` (command-line options: "--relief 0.3"
// is 0.3 mm).
double parse_quantity_or(std::string_view text, Quantity kind, std::string_view default_unit, const std::string& key);

// A length as a user types it: with its unit, or bare in `bare_unit` (a what-if: the
// instrument file's own units, see written_length_unit). `as_read` says how it was read: the
// number as typed, its unit, and mm beside when the unit is not mm ("0.012 in (0.305 mm)",
// "3/32 in (2.381 mm)", "2.2 mm").
struct LengthAsRead {
    double metres = 0.0;
    std::string as_read;
};
LengthAsRead read_length(std::string_view text, std::string_view bare_unit, const std::string& key);

// A whole number in [low, high] as an option gives it (a fret, a count), read without ever
// allocating by its size; InputError "OPTION TEXT: WHAT must be a whole number in [low, high]".
std::size_t whole_number(std::string_view text, const std::string& option, std::size_t low, std::size_t high,
                         const std::string& what);

// Turns of a screw as a user types them: "+0.25", "-1/2", "3/4 turn", "1 turns" (+ clockwise);
// InputError "OPTION TEXT: turns must be ... in [-most, most]" if it is none or out of range.
double screw_turns(std::string_view text, const std::string& option, double most);

// The frequency (Hz) of a note name such as "E1", "F#2", "Bb3"; InputError naming key if it is none.
double note_frequency(std::string_view name, const std::string& key);

}  // namespace fretbuzz
