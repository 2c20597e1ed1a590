// Fingers of a case file: `fret = k` at the top level (a finger with the default
// parameters just behind fret k), and [[finger]] tables:
//   position (m, pad centre) or fret (k: placed as `fret = k` places it), width (m),
//   mass (kg), stiffness (N/m^exponent, the whole pad), exponent, loss (s/m, Hunt-Crossley),
//   force (N toward the fretboard: a number, or [[t_s, F_N], ...] linear in between),
//   gap (m, above the string at t = 0), velocity (m/s toward the fretboard at t = 0).
// Ranges are checked with the rest of the case (Case::validate), naming these keys.
#include "CaseSections.hpp"
#include "fretbuzz/Error.hpp"

namespace fretbuzz {

namespace {

constexpr std::size_t kMaxFingerFret = 36;

void read_finger(TomlSection& s, Case& c) {
    if (const auto fret = s.optional_count("fret", 1, kMaxFingerFret)) {
        if (s.has("position"))
            throw InputError(s.key_path("position") + ": give either position or fret, not both");
        c.add_fret_finger(*fret, s.key_path("fret"));
    } else {
        c.fingers.emplace_back();
        c.fingers.back().position_m = s.number("position");
    }
    FingerSpec& f = c.fingers.back();
    f.key = s.path();
    f.width_m = s.number_or("width", f.width_m);
    f.mass_kg = s.number_or("mass", f.mass_kg);
    f.stiffness = s.number_or("stiffness", f.stiffness);
    f.exponent = s.number_or("exponent", f.exponent);
    f.loss = s.number_or("loss", f.loss);
    f.initial_gap_m = s.number_or("gap", f.initial_gap_m);
    f.initial_velocity = s.number_or("velocity", f.initial_velocity);
    if (const toml::node* force = s.node("force")) {
        if (force->is_array()) {
            f.force_profile = s.number_pairs("force");
            // Without points the finger would never press: leave the key out for a finger
            // that only strikes (a slap), or give the force.
            if (f.force_profile.empty())
                throw InputError(s.key_path("force") +
                                 " = []: an empty profile never presses; give a force in N or points [[t_s, F_N], ...] "
                                 "(or leave force out for a finger that only strikes, with a velocity)");
        }
        else
            f.force_profile = {{0.0, s.number("force")}};
        f.default_force = false;
    }
}

}  // namespace

void read_fingers(TomlSection& top, Case& c) {
    if (const auto fret = top.optional_count("fret", 1, kMaxFingerFret)) c.add_fret_finger(*fret, "fret");
    if (!top.has("finger")) return;
    for (TomlSection& s : top.sections("finger")) {
        read_finger(s, c);
        s.finish();
    }
}

}  // namespace fretbuzz
