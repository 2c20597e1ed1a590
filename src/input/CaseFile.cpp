#include "fretbuzz/input/CaseFile.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "CaseDocument.hpp"
#include "CaseSections.hpp"
#include "TomlSection.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/geometry/SimpleObstacles.hpp"
#include "fretbuzz/input/BuiltinFiles.hpp"
#include "fretbuzz/input/TextFile.hpp"

namespace fretbuzz {

DataSource DataSource::directory(std::filesystem::path dir) {
    DataSource s;
    s.dir_ = std::move(dir);
    return s;
}

DataSource DataSource::builtin() {
    DataSource s;
    s.builtin_ = true;
    return s;
}

std::string DataSource::read(const std::string& relative_path, const std::string& key) const {
    if (builtin_) {
        if (auto text = find_builtin_file(relative_path)) return std::string(*text);
        throw InputError(key + " = \"" + relative_path + "\": no such built-in data file");
    }
    const std::filesystem::path given(relative_path);
    const std::filesystem::path path = given.is_absolute() ? given : dir_ / given;
    // A case copied out with `fretbuzz show` still finds the built-in data it names.
    std::error_code ec;
    if (!given.is_absolute() && !std::filesystem::exists(path, ec) && !ec)
        if (auto text = find_builtin_file(relative_path)) return std::string(*text);
    return read_text_file(path, key + " = \"" + relative_path + "\"", kMaxDataFileBytes);
}

namespace {

constexpr std::string_view kCaseSuffix = ".toml";

void read_contact_section(TomlSection s, Case& c) {
    c.contact.law = contact_law_named(s.optional_text("law").value_or("penalty"), s.key_path("law"));
    // The impact law has no stiffness: K and alpha stay as given (or the defaults) for a later
    // switch back to the penalty.
    const bool impact = c.contact.law == ContactLawKind::impact;
    c.contact.stiffness = impact ? s.optional_positive("K").value_or(c.contact.stiffness) : s.positive("K");
    c.contact.exponent = impact ? s.number_or("alpha", c.contact.exponent) : s.number("alpha");
    require_at_least(s.key_path("alpha"), c.contact.exponent, 1.0);
    if (const auto e = s.optional_number("restitution")) {
        if (!impact)
            throw InputError(s.key_path("restitution") + " needs " + s.key_path("law") +
                             " = \"impact\" (the penalty's losses come from its exponent and the modes' damping)");
        if (!(*e >= 0.0 && *e <= 1.0))
            throw InputError(out_of_range_message(s.key_path("restitution"), *e, "must be in [0, 1]"));
        c.contact.restitution = *e;
    }
    read_friction(s, c);
    s.finish();
}

void read_run_section(TomlSection s, Case& c) {
    c.run.sample_rate_hz = s.positive("fs");
    c.run.duration_s = s.positive("duration");
    if (const toml::node* rate = s.node("output_rate")) {
        if (const auto* word = rate->as_string()) {
            if (word->get() != "native")
                throw InputError(s.key_path("output_rate") + " = \"" + word->get() + "\": must be a rate in Hz or \"native\"");
            c.run.output_rate_hz.reset();
        } else {
            c.run.output_rate_hz = s.positive("output_rate");
        }
    }
    c.run.allow_aliasing = s.optional_flag("allow_aliasing").value_or(false);
    if (s.optional_flag("lossless").value_or(false)) c.make_lossless();
    s.finish();
}

// Obstacles all lie on one side of the string: the contact solve takes one side per run.
// Points keep their exact positions (Case::point_obstacles), beside a profile too (solved with
// it), and so do a fretboard's crowns of zero width.
void combine_obstacles(std::vector<TomlSection>& sections, const DataSource& data, Case& c) {
    std::vector<std::vector<double>> obstacles;
    std::vector<PointObstacle> crowns;
    std::vector<double> frets;
    std::optional<ObstacleSide> side;
    const Grid grid{c.string.length_m, c.mode_count()};
    for (TomlSection& obstacle : sections) {
        const ObstacleSide this_side = read_obstacle_side(obstacle);
        if (side && this_side != *side)
            throw InputError(obstacle.key_path("side") + " = \"" + to_string(this_side) + "\" but " +
                             sections.front().key_path("side") + " is \"" + to_string(*side) +
                             "\": all obstacles of a case must lie on the same side of the string");
        side = this_side;
        if (is_point_section(obstacle)) {
            const std::vector<PointObstacle> points = read_point_section(obstacle, c);
            c.point_obstacles.insert(c.point_obstacles.end(), points.begin(), points.end());
            obstacles.push_back(no_obstacle(grid));
        } else {
            obstacles.push_back(read_obstacle_section(obstacle, data, c, crowns, frets));
        }
        obstacle.finish();
    }
    if (obstacles.empty()) throw InputError("obstacle: the list of obstacles is empty; use type = \"none\" for none");
    c.obstacle_above = side == ObstacleSide::above;
    // Obstacles above combine by the lowest: mirror them, take the highest, mirror back.
    const auto mirror = [](std::vector<double>& g) {
        for (double& v : g)
            if (std::isfinite(v)) v = -v;
    };
    if (c.obstacle_above) std::for_each(obstacles.begin(), obstacles.end(), mirror);
    c.obstacle_height_m = highest_of(obstacles);
    if (c.obstacle_above) mirror(c.obstacle_height_m);
    c.point_obstacles.insert(c.point_obstacles.end(), crowns.begin(), crowns.end());
    // A fretboard's frets are where it puts them, its crowns of any width (the board alone has
    // none: its end, above the body, is no fret).
    if (!frets.empty()) {
        c.fret_positions_m = std::move(frets);
        std::sort(c.fret_positions_m.begin(), c.fret_positions_m.end());
        return;
    }
    // Else only heights tell where frets are (a measured table, flat stretches, a bridge's
    // crest): those standing out toward the string, found on the heights as the solve sees
    // them, points beside a profile on their nearest grid points (a fret found there is at
    // the point's exact x); points alone (a bridge's) are no frets.
    const bool all_points = std::all_of(c.obstacle_height_m.begin(), c.obstacle_height_m.end(),
                                        [](double g) { return !std::isfinite(g); });
    std::vector<double> toward_string = all_points ? c.obstacle_height_m : c.obstacle_on_grid();
    if (c.obstacle_above) mirror(toward_string);
    c.fret_positions_m = find_frets(toward_string, c.grid_step());
    for (double& x : c.fret_positions_m)
        for (const PointObstacle& p : c.point_obstacles)
            if (std::abs(p.x_m - x) <= 0.5 * c.grid_step()) x = p.x_m;
}

void read_observe_section(TomlSection s, Case& c) {
    c.observation_points_m = s.numbers("x");
    for (std::size_t k = 0; k < c.observation_points_m.size(); ++k) {
        const double x = c.observation_points_m[k];
        if (!(x > 0.0 && x < c.string.length_m))
            throw InputError(out_of_range_message(s.key_path("x") + "[" + std::to_string(k) + "]", x,
                                                  "must lie inside the string, in (0, L) = (0, " +
                                                      std::to_string(c.string.length_m) + ") m"));
    }
    s.finish();
}

void read_audio_section(TomlSection s, Case& c) {
    c.run.audio_rate_hz = s.optional_positive("rate").value_or(c.run.audio_rate_hz);
    read_pickup_angle(s, c);
    s.finish();
}

}  // namespace

Case parse_case(std::string_view toml_text, const std::string& source_name, const DataSource& data) {
    return parse_case_document(parse_toml_document(toml_text, source_name), std::string(toml_text), data);
}

std::string toml_text(const toml::table& root) {
    std::ostringstream text;
    text << root;
    return text.str();
}

Case parse_case_document(const toml::table& root, std::string source_text, const DataSource& data) {
    TomlSection top(root, "");
    Case c;
    c.source_text = std::move(source_text);
    c.name = top.text("name");
    c.description = top.optional_text("description").value_or("");
    StringDescription string;
    {
        TomlSection section = top.section("string");
        string = read_string_section(section, c);
        read_polarisation_count(section, c);
        section.finish();
    }
    {
        // An ideal string needs no [modes] table at all: its frequencies are j c / (2L).
        std::optional<TomlSection> modes =
            string.ideal ? top.optional_section("modes") : std::optional<TomlSection>(top.section("modes"));
        const toml::table empty;
        TomlSection none(empty, "modes");
        // run.lossless is read with [run]; the mode table needs to know it now.
        const auto* run = root["run"].as_table();
        const bool lossless = run != nullptr && (*run)["lossless"].value_or(false);
        read_modes_section(modes ? *modes : none, data, string, lossless, c);
        if (modes) modes->finish();
    }
    // One obstacle, or several ([[obstacle]]) that the string meets wherever each is highest.
    std::vector<TomlSection> obstacle_sections = top.sections("obstacle");
    combine_obstacles(obstacle_sections, data, c);
    {
        TomlSection excitation = top.section("excitation");
        read_excitation_section(excitation, data, c);
        read_excitation_angle(excitation, c);
        excitation.finish();
    }
    read_contact_section(top.section("contact"), c);
    read_run_section(top.section("run"), c);
    read_observe_section(top.section("observe"), c);
    read_fingers(top, c);
    read_gestures(top, c);
    if (auto audio = top.optional_section("audio")) read_audio_section(*audio, c);
    if (auto y = top.optional_section("polarisation_y")) {
        read_polarisation_y_section(*y, data, c);
        if (root["run"]["lossless"].value_or(false)) c.make_lossless();  // the y table too
    }
    top.finish();
    return c;
}

std::vector<BuiltinCaseInfo> builtin_cases() {
    std::vector<BuiltinCaseInfo> cases;
    for (const EmbeddedFile& f : builtin_files()) {
        const std::string_view name = f.name;
        if (name.find('/') != std::string_view::npos || !name.ends_with(kCaseSuffix)) continue;
        const toml::table root = parse_toml_document(f.text(), std::string(name));
        cases.push_back({std::string(name.substr(0, name.size() - kCaseSuffix.size())),
                         root["description"].value_or(std::string())});
    }
    return cases;
}

bool is_builtin_case(std::string_view name) {
    return find_builtin_file(std::string(name) + std::string(kCaseSuffix)).has_value();
}

std::string builtin_case_text(std::string_view name) {
    if (auto text = find_builtin_file(std::string(name) + std::string(kCaseSuffix))) return std::string(*text);
    std::string names;
    for (const auto& info : builtin_cases()) names += (names.empty() ? "" : ", ") + info.name;
    throw InputError("unknown case '" + std::string(name) + "': give a built-in case (" + names +
                     ") or the path of a .toml case file");
}

CaseText read_case_text(const std::string& name_or_path) {
    if (is_builtin_case(name_or_path))
        return {builtin_case_text(name_or_path), name_or_path + ".toml", DataSource::builtin()};
    const std::filesystem::path path(name_or_path);
    if (path.extension() == kCaseSuffix) {
        return {read_text_file(path, "case file " + path.string(), kMaxCaseFileBytes), path.string(),
                DataSource::directory(path.parent_path())};
    }
    builtin_case_text(name_or_path);  // throws the list of valid names
    return {};
}

Case load_case(const std::string& name_or_path) {
    const CaseText source = read_case_text(name_or_path);
    return parse_case(source.text, source.source_name, source.data);
}

Case with_mode_count(const CaseText& source, std::size_t modes) {
    toml::table root = parse_toml_document(source.text, source.source_name);
    // Point obstacles keep the contact width they had at the case's own mode count (their
    // default width is its grid step): the same points, only the modes change.
    const Case as_written = parse_case_document(root, source.text, source.data);
    const double width = as_written.grid_step();
    const auto keep_width = [&](toml::table& obstacle) {
        if (obstacle["type"].value_or(std::string()) == "points" && !obstacle.contains("width"))
            obstacle.insert_or_assign("width", width);
    };
    if (toml::table* one = root["obstacle"].as_table()) keep_width(*one);
    if (toml::array* several = root["obstacle"].as_array())
        for (toml::node& node : *several)
            if (toml::table* t = node.as_table()) keep_width(*t);
    if (toml::table* string = root["string"].as_table())
        string->insert_or_assign("modes", static_cast<std::int64_t>(modes));
    return parse_case_document(root, toml_text(root), source.data);
}

}  // namespace fretbuzz
