// [obstacle] type = "fretboard", with its frets in [obstacle.frets]:
//   scale_length (default L), action_nut, action_last_fret, relief (a bow depth, or
//   [[x, depth], ...]), board_end (default: the last fret), body_height (optional);
//   frets: count, height, crown_width (default 0: one grid point per fret),
//   height_offsets ({ n = m }: fret n's top raised by m, lowered if negative).
#include <cmath>
#include <sstream>

#include "FretboardSection.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/geometry/Fretboard.hpp"

namespace fretbuzz {

namespace {

constexpr double kMaxAction = 0.05;  // m: far above any playable setup
constexpr double kMaxFretOffset = 1e-3;  // m: a fret 1 mm proud stops every note below it

double action(TomlSection& s, std::string_view key) {
    const double a = s.non_negative(key);
    if (a > kMaxAction) throw InputError(out_of_range_message(s.key_path(key), a, "must be in [0, 0.05] m"));
    return a;
}

void read_frets(TomlSection s, Fretboard& board) {
    board.fret_count = s.count("count", 1, 36);
    board.fret_height_m = s.positive("height");
    if (board.fret_height_m > 0.01)
        throw InputError(out_of_range_message(s.key_path("height"), board.fret_height_m, "must be in (0, 0.01] m"));
    // A fret may stand up to 1 mm proud of the fret line, or be worn down to the board.
    board.fret_height_offset_m = s.numbered_numbers("height_offsets", 1, board.fret_count);
    for (const auto& [n, offset] : board.fret_height_offset_m)
        if (!(offset >= -board.fret_height_m && offset <= kMaxFretOffset)) {
            std::ostringstream allowed;
            allowed << "must be in [-" << board.fret_height_m << ", 0.001] m (down to the board at most)";
            throw InputError(out_of_range_message(s.key_path("height_offsets." + std::to_string(n)), offset,
                                                  allowed.str()));
        }
    board.crown_width_m = s.optional_non_negative("crown_width").value_or(0.0);
    if (board.crown_width_m > 0.02)
        throw InputError(
            out_of_range_message(s.key_path("crown_width"), board.crown_width_m, "must be in [0, 0.02] m"));
    s.finish();
}

NeckRelief read_relief(TomlSection& s, double last_fret) {
    if (!s.has("relief")) return NeckRelief::straight();
    const toml::node* node = s.node("relief");
    if (!node->is_array()) {
        const double depth = s.number("relief");
        if (!(std::abs(depth) <= 0.01))
            throw InputError(out_of_range_message(s.key_path("relief"), depth, "must be in [-0.01, 0.01] m"));
        return NeckRelief::bow(depth);
    }
    std::vector<double> x, depth;
    for (const auto& [xk, dk] : s.number_pairs("relief")) {
        const std::string item = s.key_path("relief") + "[" + std::to_string(x.size()) + "]";
        if (!(xk > 0.0 && xk < last_fret))
            throw InputError(out_of_range_message(item + "[0] (x)", xk,
                                                  "must lie between the nut and the last fret, in (0, " +
                                                      std::to_string(last_fret) + ") m"));
        if (!x.empty() && !(xk > x.back()))
            throw InputError(out_of_range_message(item + "[0] (x)", xk, "must increase from point to point"));
        if (!(std::abs(dk) <= 0.01))
            throw InputError(out_of_range_message(item + "[1] (depth)", dk, "must be in [-0.01, 0.01] m"));
        x.push_back(xk);
        depth.push_back(dk);
    }
    return NeckRelief::curve(std::move(x), std::move(depth));
}

}  // namespace

std::vector<double> read_fretboard(TomlSection& s, const Grid& grid, std::vector<PointObstacle>& points,
                                   std::vector<double>& frets) {
    Fretboard board;
    board.scale_length_m = s.optional_positive("scale_length").value_or(grid.length_m);
    read_frets(s.section("frets"), board);
    const double last_fret = board.fret_position(board.fret_count);
    if (!(last_fret < grid.length_m))
        throw InputError(out_of_range_message(s.key_path("frets.count"), static_cast<double>(board.fret_count),
                                              "puts the last fret at x = " + std::to_string(last_fret) +
                                                  " m, beyond the string's length L"));
    board.action_at_nut_m = action(s, "action_nut");
    board.action_at_last_fret_m = action(s, "action_last_fret");
    board.relief = read_relief(s, last_fret);
    board.board_end_m = last_fret;
    if (s.has("board_end")) {
        board.board_end_m = s.number("board_end");
        if (!(board.board_end_m >= last_fret && board.board_end_m <= grid.length_m))
            throw InputError(out_of_range_message(s.key_path("board_end"), board.board_end_m,
                                                  "must lie between the last fret (x = " + std::to_string(last_fret) +
                                                      " m) and L"));
    }
    if (s.has("body_height")) {
        const double body = s.number("body_height");
        if (!(std::abs(body) <= 0.1))
            throw InputError(out_of_range_message(s.key_path("body_height"), body, "must be in [-0.1, 0.1] m"));
        board.body_height_m = body;
    }
    for (std::size_t n = 1; n <= board.fret_count; ++n) frets.push_back(board.fret_position(n));
    if (!board.point_crowns()) return board.sample(grid);
    for (const auto& [x, top] : board.crowns()) points.push_back({x, top, grid.step()});
    return board.sample_board(grid);
}

}  // namespace fretbuzz
