// [[gesture]] tables: gestures in time. type = "force": a prescribed force F(t) at a point
// or over a pad: position (m), width (m, default 0: a point force at its exact position), direction
// ("down", toward the fretboard, the default, or "up"), angle (degrees from z toward y, two
// polarisations), force (N: a number, or [[t_s, F_N], ...] linear in between). type = "pluck"
// (direction "up" or "down", required) or "pop" (always "up"): a plucker on a prescribed path,
// see PluckSpec and scheme/Pluck.hpp for its keys. Ranges are checked with the rest of the
// case (Case::validate), naming these keys.
#include "CaseSections.hpp"
#include "fretbuzz/Error.hpp"

namespace fretbuzz {

namespace {

void read_pluck(TomlSection& s, bool pop, Case& c) {
    PluckSpec f;
    f.key = s.path();
    f.pop = pop;
    f.position_m = s.number("position");
    f.width_m = s.number_or("width", f.width_m);
    const std::string direction = pop ? s.optional_text("direction").value_or("up") : s.text("direction");
    if (direction != "up" && (pop || direction != "down"))
        throw InputError(s.key_path("direction") + " = \"" + direction + "\": must be " +
                         (pop ? "\"up\" (a pop pulls the string away from the fretboard)" : "\"down\" or \"up\""));
    f.direction = direction == "down" ? 1.0 : -1.0;
    f.start_s = s.number_or("time", f.start_s);
    f.gap_m = s.number_or("gap", f.gap_m);
    f.stiffness = s.number_or("stiffness", f.stiffness);
    f.exponent = s.number_or("exponent", f.exponent);
    f.loss = s.number_or("loss", f.loss);
    f.release_force_n = s.number_or("release_force", f.release_force_n);
    f.release_displacement_m = s.number_or("release_displacement", f.release_displacement_m);
    f.withdraw_speed = s.number_or("withdraw_speed", f.withdraw_speed);
    if (s.has("duration")) {
        // The time to travel the release displacement from the string's rest line.
        if (s.has("speed")) throw InputError(s.key_path("duration") + ": give either speed or duration, not both");
        const double duration = s.number("duration");
        if (!(f.release_displacement_m > 0.0))
            throw InputError(s.key_path("duration") + ": needs release_displacement > 0 (the distance it takes that long to travel)");
        if (!(duration >= f.release_displacement_m / 100.0 && duration <= 10.0))
            throw InputError(out_of_range_message(s.key_path("duration") + " (s)", duration,
                                                  "must be in [release_displacement / (100 m/s), 10] s"));
        f.speed = f.release_displacement_m / duration;
    } else {
        f.speed = s.number_or("speed", f.speed);
    }
    c.plucks.push_back(std::move(f));
}

}  // namespace

void read_gestures(TomlSection& top, Case& c) {
    if (!top.has("gesture")) return;
    for (TomlSection& s : top.sections("gesture")) {
        const std::string type = s.text("type");
        if (type == "pluck" || type == "pop") {
            read_pluck(s, type == "pop", c);
            s.finish();
            continue;
        }
        if (type != "force")
            throw InputError(s.key_path("type") + " = \"" + type +
                             "\": must be \"force\", \"pluck\" or \"pop\" (a slap is a [[finger]] with a velocity and no force)");
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
