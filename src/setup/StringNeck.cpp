#include "fretbuzz/setup/StringNeck.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "MillimetreText.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/geometry/FretPositions.hpp"
#include "fretbuzz/geometry/Fretboard.hpp"
#include "fretbuzz/geometry/SimpleObstacles.hpp"

namespace fretbuzz {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// A parabolic bow of depth 1 at mid-span, zero at the nut end and at the last fret: the
// fretboard's relief bow (geometry/Fretboard.hpp), so both necks bow alike.
double unit_bow(double x, double last) { return NeckRelief::bow(1.0).depth_at(x, last); }

// How much the relief gap over fret m grows per metre of bow depth (frets at x, 0..N).
double gap_per_bow(const std::vector<double>& x, std::size_t m) {
    const std::size_t n = x.size() - 1;
    const double b1 = unit_bow(x[1], x[n]), bm = unit_bow(x[m], x[n]);
    return bm - b1 * (x[n] - x[m]) / (x[n] - x[1]);
}

// The fretboard radius as one string sees it: the string runs from y_nut to y_bridge off the
// neck's centre line over a cylinder of radius R, so the fret tops under it drop by
// R - sqrt(R^2 - y^2); relative to the fret plane (the chord from the nut end to the last
// fret) that leaves a crown of depth about (dy/dx)^2 / (2 R) x (x_N - x). A compound board is
// a cone: its radius grows linearly from R at the nut to R_N at the last fret.
double radius_crown(double x, double last, double length, double radius, double radius_last, double y_nut,
                    double y_bridge) {
    const auto drop = [&](double at) {
        const double y = y_nut + (y_bridge - y_nut) * at / length;
        const double r = radius + (radius_last - radius) * at / last;
        return r - std::sqrt(r * r - y * y);
    };
    const double chord = drop(0.0) + (drop(last) - drop(0.0)) * x / last;
    return chord - drop(x);
}

double interpolate(const std::vector<double>& xs, const std::vector<double>& zs, double x) {
    if (x <= xs.front()) return zs.front();
    if (x >= xs.back()) return zs.back();
    const auto upper = std::upper_bound(xs.begin(), xs.end(), x);
    const std::size_t j = static_cast<std::size_t>(upper - xs.begin());
    return zs[j - 1] + (zs[j] - zs[j - 1]) * (x - xs[j - 1]) / (xs[j] - xs[j - 1]);
}

}  // namespace

double strings_pull(const Instrument& instrument) {
    double pull = 0.0;
    for (const InstrumentString& s : instrument.strings) pull += s.tension_n;
    return pull;
}

double pull_bow(const Instrument& instrument, double span_m) {
    const NeckDescription& neck = instrument.neck;
    if (!neck.relief_pull_n) return 0.0;
    return neck.beam.bow_per_newton(span_m) * (strings_pull(instrument) - *neck.relief_pull_n);
}

double relief_gap_per_bow(const StringNeck& neck, std::size_t at_fret) {
    std::vector<double> x;
    for (std::size_t n = 0; n <= neck.fret_count(); ++n) x.push_back(neck.fret_x(n));
    return gap_per_bow(x, at_fret);
}

StringNeck::StringNeck(const Instrument& instrument, std::size_t string) {
    const InstrumentString& s = instrument.strings.at(string);
    const NeckDescription& neck = instrument.neck;
    const std::size_t frets = neck.fret_count;
    const std::string key = "string[" + std::to_string(string) + "]";  // the [[string]] table it came from
    name_ = s.name;
    length_ = s.scale_length_m;
    fret_height_ = neck.fret_height_m;
    x_.assign(frets + 1, 0.0);
    line_.assign(frets + 1, 0.0);
    double profile_nut = 0.0, profile_saddle = 0.0;
    if (!s.profile_x_m.empty()) {
        // A measured profile under the open string at rest (z = 0): its frets stand out above
        // both neighbours, one grid point each. A scan gives heights only, so the peak finder
        // tells where its frets are (each then at its sample's exact x).
        measured_ = true;
        const std::vector<double>& px = s.profile_x_m;
        const std::vector<double>& pz = s.profile_height_m;
        const double dx = px.front();
        for (std::size_t i = 0; i < px.size(); ++i)
            if (std::abs(px[i] - static_cast<double>(i + 1) * dx) > 1e-6 * dx)
                throw InputError(key + ".profile = \"" + s.profile_source +
                                 "\": the points must lie on a regular grid x_i = i dx from the nut (row " +
                                 std::to_string(i + 1) + " does not)");
        const std::vector<double> found = find_frets(pz, dx);
        if (found.size() != frets)
            throw InputError(key + ".profile = \"" + s.profile_source + "\" has " + std::to_string(found.size()) +
                             " frets but neck.frets = " + std::to_string(frets));
        std::vector<char> fret_point(px.size(), 0);
        for (std::size_t n = 1; n <= frets; ++n) {
            const auto i = static_cast<std::size_t>(std::lround(found[n - 1] / dx)) - 1;
            fret_point[i] = 1;
            x_[n] = px[i];
            line_[n] = pz[i];
        }
        // The fret plane: from the fret line extended to the nut (through frets 1 and 2) to the last fret.
        line_[0] = line_[1] - (line_[2] - line_[1]) * x_[1] / (x_[2] - x_[1]);
        const double z0 = line_[0], zn = line_[frets], last = x_[frets];
        const auto plane = [=](double x) { return z0 + (zn - z0) * x / last; };
        for (std::size_t n = 0; n <= frets; ++n) line_[n] -= plane(x_[n]);
        for (std::size_t i = 0; i < px.size(); ++i)
            if (!fret_point[i]) {
                board_x_.push_back(px[i]);
                board_z_.push_back(pz[i] - plane(px[i]));
            }
        board_end_ = px.back();
        profile_nut = -plane(0.0);
        profile_saddle = -plane(length_);
    } else {
        for (std::size_t n = 0; n <= frets; ++n) x_[n] = fret_position(length_, n);
        const double last = x_[frets];
        if (!s.scan_m.empty()) {
            // Tops measured above the straightedge on fret 1 and the last fret; the plane
            // runs from the fret line extended to the nut to the last fret.
            for (std::size_t n = 1; n <= frets; ++n) line_[n] = s.scan_m.at(n);
            line_[0] = line_[1] - (line_[2] - line_[1]) * x_[1] / (x_[2] - x_[1]);
            const double z0 = line_[0], zn = line_[frets];
            for (std::size_t n = 0; n <= frets; ++n) line_[n] -= z0 + (zn - z0) * x_[n] / last;
        } else {
            // The radius first: the measured relief gap is read under the first string, crown included.
            const auto crown = [&](std::size_t which, const std::vector<double>& xs) {
                std::vector<double> c(xs.size(), 0.0);
                if (!neck.radius_m || instrument.strings.size() < 2) return c;
                const double place =
                    static_cast<double>(which) / static_cast<double>(instrument.strings.size() - 1) - 0.5;
                const double l = instrument.strings[which].scale_length_m;
                const double at_nut = *neck.radius_m, at_last = neck.radius_last_fret_m.value_or(at_nut);
                for (std::size_t n = 0; n < xs.size(); ++n)
                    c[n] = radius_crown(xs[n], xs.back(), l, at_nut, at_last, place * neck.nut_width_m,
                                        place * neck.bridge_spacing_m);
                return c;
            };
            line_ = crown(string, x_);
            const ReliefMeasure& relief = neck.relief;
            if (relief.form == ReliefMeasure::Form::curve) {
                const NeckRelief curve = NeckRelief::curve(relief.x_m, relief.depth_m);
                for (std::size_t n = 1; n < frets; ++n) line_[n] -= curve.depth_at(x_[n], last);
            } else if (relief.form == ReliefMeasure::Form::gap) {
                std::vector<double> x0(frets + 1);
                for (std::size_t n = 0; n <= frets; ++n) x0[n] = fret_position(instrument.strings[0].scale_length_m, n);
                const std::vector<double> c0 = crown(0, x0);
                const std::size_t m = relief.at_fret;
                const double crown_gap = c0[1] + (c0[frets] - c0[1]) * (x0[m] - x0[1]) / (x0[frets] - x0[1]) - c0[m];
                const double depth = (relief.gap_m - crown_gap) / gap_per_bow(x0, m);
                const NeckRelief bowed = NeckRelief::bow(depth);
                for (std::size_t n = 1; n < frets; ++n) line_[n] -= bowed.depth_at(x_[n], last);
            }
        }
        board_x_ = x_;
        for (double z : line_) board_z_.push_back(z - fret_height_);
        board_end_ = std::min(neck.board_end_m, 0.5 * (last + length_));
        if (board_end_ > last) {
            board_x_.push_back(board_end_);
            board_z_.push_back(board_z_.back());
        }
    }
    // The truss rod (what-ifs) and the strings pulling more or less than when the relief was
    // measured: a bow down toward mid-span, zero at the nut end and the last fret.
    const double bow = neck.truss_rod_bow_m + pull_bow(instrument, x_[frets]);
    if (bow != 0.0) {
        const double last = x_[frets];
        const NeckRelief bowed = NeckRelief::bow(bow);
        for (std::size_t n = 0; n <= frets; ++n) line_[n] -= bowed.depth_at(x_[n], last);
        for (std::size_t j = 0; j < board_x_.size(); ++j) board_z_[j] -= bowed.depth_at(board_x_[j], last);
    }
    top_ = line_;
    for (const auto& [n, offset] : neck.fret_offset_m) top_.at(n) += offset;

    // The open string through its two measured ends.
    const auto end_point = [&](const StringEnd& e, bool nut) -> std::pair<double, double> {
        switch (e.form) {
            case StringEnd::Form::gap_over_fret: return {x_.at(e.fret), top_.at(e.fret) + e.value_m};
            case StringEnd::Form::height: return {nut ? 0.0 : length_, e.value_m};
            case StringEnd::Form::as_measured: return {nut ? 0.0 : length_, nut ? profile_nut : profile_saddle};
        }
        return {};
    };
    const auto [xa, za] = end_point(s.nut, true);
    const auto [xb, zb] = end_point(s.bridge, false);
    nut_height_ = za + (zb - za) * (0.0 - xa) / (xb - xa);
    saddle_height_ = za + (zb - za) * (length_ - xa) / (xb - xa);
    // The body: fixed to the neck, parallel to the fret plane, as deep below the open
    // string at the board's end as the file says (or where pinning the string's ends put it).
    if (s.body_height_m)
        body_ = *s.body_height_m;
    else if (neck.body_depth_m && !measured_)
        body_ = string_height(board_end_) - *neck.body_depth_m;
    for (std::size_t n = 1; n <= frets; ++n)
        if (!(gap(n) > 0.0))
            throw InputError(key + " (" + name_ + "): the open string would lie on fret " + std::to_string(n) +
                             " (its gap there is " + mm_text(gap(n)) + "): with this relief and these frets, " + key +
                             ".nut and its action must put the open string above every fret (raise the action)");
}

double StringNeck::surface(double x) const {
    if (x <= board_end_) return interpolate(board_x_, board_z_, x);
    if (body_) return *body_;
    return -kInfinity;
}

double StringNeck::relief_gap(std::size_t m) const {
    const std::size_t n = fret_count();
    const double chord = top_[1] + (top_[n] - top_[1]) * (x_[m] - x_[1]) / (x_[n] - x_[1]);
    return chord - top_[m];
}

double StringNeck::rest_height(std::size_t k, double x) const {
    if (k == 0) return string_height(x);
    return top_[k] + (saddle_height_ - top_[k]) * (x - x_[k]) / (length_ - x_[k]);
}

std::optional<std::size_t> StringNeck::rests_on(std::size_t k) const {
    for (std::size_t n = k + 1; n <= fret_count(); ++n)
        if (!(clearance(k, n) > 0.0)) return n;
    for (double x = x_[k] + 5e-4; x < length_; x += 5e-4)
        if (surface(x) >= rest_height(k, x)) return 0;
    return std::nullopt;
}

std::vector<double> StringNeck::note_board(std::size_t k, const Grid& grid) const {
    std::vector<double> g(grid.points);
    const double xk = x_[k];
    for (std::size_t i = 0; i < grid.points; ++i) {
        const double x = xk + grid.x(i);
        const double z = surface(x);
        g[i] = std::isfinite(z) ? z - rest_height(k, x) : -kInfinity;
    }
    return g;
}

std::vector<PointObstacle> StringNeck::note_frets(std::size_t k, const Grid& grid) const {
    std::vector<PointObstacle> frets;
    for (std::size_t n = k + 1; n <= fret_count(); ++n)
        frets.push_back({x_[n] - x_[k], top_[n] - rest_height(k, x_[n]), grid.step()});
    return frets;
}

std::vector<double> StringNeck::note_obstacle(std::size_t k, const Grid& grid) const {
    std::vector<double> g = note_board(k, grid);
    for (const PointObstacle& p : note_frets(k, grid)) {
        double& at = g[nearest_grid_point(grid, p.x_m)];
        at = std::max(at, p.height_m);
    }
    return g;
}

}  // namespace fretbuzz
