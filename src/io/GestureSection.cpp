// [[gesture]] tables: gestures in time. type = "force": a prescribed force F(t) at a point
// or over a pad: position (m), width (m, default 0: the nearest grid point), direction
// ("down", toward the fretboard, the default, or "up"), angle (degrees from z toward y, two
// polarisations), force (N: a number, or
// [[t_s, F_N], ...] linear in between). Ranges are checked with the rest of the case
// (Case::validate), naming these keys.
#include "CaseSections.hpp"
#include "fretbuzz/Error.hpp"

namespace fretbuzz {

void read_gestures(TomlSection& top, Case& c) {
    if (!top.has("gesture")) return;
    for (TomlSection& s : top.sections("gesture")) {
        const std::string type = s.text("type");
        if (type != "force")
            throw InputError(s.key_path("type") + " = \"" + type +
                             "\": must be \"force\" (a slap is a [[finger]] with a velocity and no force)");
        ForceSpec f;
        f.key = s.path();
        f.position_m = s.number("position");
        f.width_m = s.number_or("width", 0.0);
        const std::string direction = s.optional_text("direction").value_or("down");
        if (direction != "down" && direction != "up")
            throw InputError(s.key_path("direction") + " = \"" + direction + "\": must be \"down\" or \"up\"");
        f.direction = direction == "down" ? 1.0 : -1.0;
        f.angle_deg = s.optional_number("angle").value_or(0.0);
        if (const toml::node* force = s.node("force"); force != nullptr && force->is_array())
            f.force_profile = s.number_pairs("force");
        else
            f.force_profile = {{0.0, s.number("force")}};
        c.forces.push_back(std::move(f));
        s.finish();
    }
}

}  // namespace fretbuzz
