#include "fretbuzz/setup/NoteCase.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <numeric>
#include <numbers>
#include <random>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/geometry/InitialShape.hpp"
#include "fretbuzz/model/FrequencyModel.hpp"
#include "fretbuzz/model/ModeTableAssembly.hpp"
#include "fretbuzz/model/WavenumberDamping.hpp"
#include "fretbuzz/input/StoppedString.hpp"
#include "fretbuzz/numerics/Lcp.hpp"
#include "fretbuzz/numerics/ModalBasis.hpp"
#include "fretbuzz/scheme/SamplingCheck.hpp"

namespace fretbuzz {

namespace {

// The finger model's pick: the finger lands first (the default `fret = k` finger presses
// 0 to 5 N over 5 ms), then the pick pulls for whole periods of the note (a linear ramp of
// whole periods leaves an oscillator at rest on its new equilibrium) and lets go.
constexpr double kFingerSettles = 6e-3;
constexpr double kPullPeriods = 2.0;
constexpr double kRelease = 1e-4;

std::size_t grid_points(double length, double step) {
    return static_cast<std::size_t>(std::max(2L, std::lround(length / step) - 1));
}

// stopped_string of an obstacle-free open string, its held modes kept for the process: they
// cost tens of ms per note and do not change with the set-up (relief, action, frets), so a
// what-if after a map, or a search playing the same string again and again, finds them here.
// Only what the key says is kept: the modes (and a measured second polarisation's), from the
// open string's modes and length, tension and density, the stop and the count. Everything
// else of the stopped string (its contact law, friction, run, names) is the caller's own
// `bare`, so two instruments with other contact laws in one process play each with its own.
Case held_string(const Case& bare, double stop, std::size_t modes) {
    struct Key {
        std::vector<double> values;
        bool operator==(const Key&) const = default;
    };
    struct Held {
        ModeTable modes, second;
    };
    static std::mutex mutex;
    static std::vector<std::pair<Key, std::shared_ptr<const Held>>> kept;
    constexpr std::size_t kMaxKept = 512;
    Key key{{bare.string.length_m, bare.string.tension_n, bare.string.linear_density, stop,
             static_cast<double>(modes), static_cast<double>(bare.mode_count()),
             static_cast<double>(bare.polarisation.table.size())}};
    for (const ModeTable* t : {&bare.modes, &bare.polarisation.table}) {
        key.values.insert(key.values.end(), t->frequency_hz.begin(), t->frequency_hz.end());
        key.values.insert(key.values.end(), t->sigma_per_s.begin(), t->sigma_per_s.end());
    }
    const auto made_of = [&](const Held& held) {
        Case c = bare;
        c.string.length_m = bare.string.length_m - stop;
        c.modes = held.modes;
        c.polarisation.table = held.second;
        const std::size_t n = c.mode_count();
        c.initial_displacement.assign(n, 0.0);
        c.initial_velocity.assign(n, 0.0);
        c.obstacle_height_m.assign(n, -std::numeric_limits<double>::infinity());
        return c;
    };
    {
        std::lock_guard lock(mutex);
        for (const auto& [k, held] : kept)
            if (k == key) return made_of(*held);
    }
    const Case stopped = stopped_string(bare, stop, modes);
    auto held = std::make_shared<const Held>(Held{stopped.modes, stopped.polarisation.table});
    {
        std::lock_guard lock(mutex);
        if (kept.size() >= kMaxKept) kept.clear();
        kept.emplace_back(std::move(key), held);
    }
    return made_of(*held);
}

// The neck under the note stopped at fret k on the case's grid: the board on the grid points,
// the frets past k at their exact positions (as a case file's crowns of zero width), which
// are the case's frets.
void place_neck(Case& c, const StringNeck& neck, std::size_t k) {
    const Grid grid{c.string.length_m, c.mode_count()};
    c.obstacle_height_m = neck.note_board(k, grid);
    c.point_obstacles = neck.note_frets(k, grid);
    c.fret_positions_m.clear();
    for (const PointObstacle& p : c.point_obstacles) c.fret_positions_m.push_back(p.x_m);
}

// A string at rest over the frets: its modes are the sine interpolant of its grid shape, which
// dips below a fret that the shape bends over between grid points (by up to tens of um where
// a big pluck wraps the string over a fret onto the board). The frets lift it there by the
// string's own response to point forces on them (triangles with their corners on the frets),
// pushing up only, each until the string clears its top by a picometre: the complementarity
// problem of the string resting on the frets it meets.
void rest_on_frets(const Case& c, const ModalBasis& basis, const Grid& grid, std::vector<double>& q) {
    constexpr double kAbove = 1e-12;  // m, as taut_over_obstacle's
    const std::size_t m = c.point_obstacles.size();
    std::vector<std::vector<double>> phi(m);
    std::vector<double> gap(m);
    bool below = false;
    for (std::size_t p = 0; p < m; ++p) {
        phi[p] = basis.mode_shapes_at(c.point_obstacles[p].x_m);
        gap[p] = std::inner_product(phi[p].begin(), phi[p].end(), q.begin(), 0.0) -
                 (c.point_obstacles[p].height_m + kAbove);
        below |= gap[p] < 0.0;
    }
    if (!below) return;
    std::vector<std::vector<double>> corner(m, std::vector<double>(q.size()));
    std::vector<double> matrix(m * m), lift(m);
    for (std::size_t p = 0; p < m; ++p) {
        basis.to_modes(triangle_shape(grid, c.point_obstacles[p].x_m, 1.0), corner[p]);
        for (std::size_t r = 0; r < m; ++r)
            matrix[r * m + p] = std::inner_product(phi[r].begin(), phi[r].end(), corner[p].begin(), 0.0);
    }
    // (no solution: left as it is, and the case's check names the fret it goes into)
    if (!LemkeSolver(m).solve(matrix, gap, m, lift)) return;
    for (std::size_t p = 0; p < m; ++p)
        for (std::size_t j = 0; j < q.size(); ++j) q[j] += lift[p] * corner[p][j];
}

}  // namespace

NoteMaker::NoteMaker(const Instrument& instrument, std::size_t string)
    : string_(string),
      neck_(instrument, string),
      observe_from_bridge_m_(instrument.bench.observe_from_bridge_m),
      grid_step_m_(instrument.bench.grid_step_m),
      pinned_(instrument.bench.pinned_stops),
      bending_stiffness_(instrument.strings.at(string).bending_stiffness),
      eta0_(instrument.bench.damping_eta0),
      eta2_(instrument.bench.damping_eta2),
      fret_friction_(instrument.bench.fret_friction),
      thumb_mass_(instrument.attack.thumb_mass_kg),
      thumb_stiffness_(instrument.attack.thumb_stiffness),
      thumb_loss_(instrument.attack.thumb_loss),
      scatter_cents_(instrument.bench.partial_scatter_cents),
      seed_(instrument.attack.seed) {
    const InstrumentString& s = instrument.strings.at(string);
    const BenchSettings& b = instrument.bench;
    const double length = s.scale_length_m;
    open_.name = instrument.name + "-" + s.name;
    open_.description = "string " + s.name + " of " + instrument.name;
    open_.string = {length, s.tension_n, s.linear_density};
    const std::size_t n = grid_points(length, b.grid_step_m);
    open_.modes = string_modes(length, n);
    place_neck(open_, neck_, 0);
    open_.initial_displacement.assign(n, 0.0);
    open_.initial_velocity.assign(n, 0.0);
    open_.contact = {b.contact_stiffness, b.contact_exponent, b.contact_law, b.restitution};
    open_.run.sample_rate_hz = b.sample_rate_hz;
    open_.run.duration_s = b.duration_s;
    open_.run.output_rate_hz = b.output_rate_hz;
    open_.observation_points_m = {length - b.observe_from_bridge_m};
    bare_ = open_;
    bare_.obstacle_height_m.assign(n, -std::numeric_limits<double>::infinity());
    bare_.point_obstacles.clear();
    bare_.fret_positions_m.clear();
    stopped_.resize(neck_.fret_count() + 1);
    once_ = std::vector<std::once_flag>(neck_.fret_count() + 1);
}

// Real strings' partials stray from any smooth law by a cent or so (the paper's measured G
// string: 0.8 to 1.3 cents rms from its fitted B law over its first 10 to 40 modes); the
// scatter is drawn once per note, from the instrument's seed, the string and the fret.
void NoteMaker::scatter(ModeTable& modes, std::size_t fret) const {
    if (!(scatter_cents_ > 0.0)) return;
    std::seed_seq seq{seed_, static_cast<unsigned long long>(string_), static_cast<unsigned long long>(fret), 0x5ca7ull};
    std::mt19937_64 random(seq);
    std::normal_distribution<double> cents(0.0, scatter_cents_);
    for (double& f : modes.frequency_hz) f *= std::exp2(cents(random) / 1200.0);
}

ModeTable NoteMaker::string_modes(double length, std::size_t modes) const {
    const TautString taut{length, open_.string.tension_n, open_.string.linear_density};
    const FrequencyModel frequency(taut, taut.inharmonicity_for(bending_stiffness_));
    const WavenumberDamping damping(length, eta0_, eta2_);
    return assemble_mode_table(modes, {}, &frequency, &damping);
}

double NoteMaker::pluck_position(double sounding, const Attack& attack, const PluckVariation& pluck) const {
    return sounding - (attack.where.from_bridge_m + pluck.shift_m);
}

double NoteMaker::fundamental_hz(std::size_t fret) const { return stopped(fret).modes.frequency_hz.front(); }

std::optional<std::string> NoteMaker::unplayable(std::size_t fret, const Attack& attack, const PluckVariation& pluck,
                                                 bool finger) const {
    const double sounding = neck_.length() - neck_.fret_x(fret);
    const double x = pluck_position(sounding, attack, pluck);
    if (finger && attack.strike())
        return std::string("the finger model plays plucks and pops; slap the stand-in (no --finger)");
    if (!(x - 0.5 * attack.where.width_m > 0.0 && x + 0.5 * attack.where.width_m < sounding))
        return "the pluck (" + std::to_string(1e3 * (attack.where.from_bridge_m + pluck.shift_m)) +
               " mm from the bridge) falls behind fret " + std::to_string(fret);
    if (sounding - observe_from_bridge_m_ <= 0.0) return std::string("the pickup lies behind the fret");
    return std::nullopt;
}

double z_share(const Attack& attack, const PluckVariation& pluck) {
    const double angle = std::clamp(attack.where.angle_deg + pluck.turn_deg, -90.0, 90.0);
    return -attack.size * pluck.scale * std::sin(angle * std::numbers::pi / 180.0);
}

void NoteMaker::excite(Case& c, const Attack& attack, const PluckVariation& pluck, Polarisations polarisations) const {
    const std::size_t n = c.mode_count();
    const Grid grid{c.string.length_m, n};
    const ModalBasis basis(c.string.length_m, n);
    const double x = pluck_position(c.string.length_m, attack, pluck);  // from the bridge, on either model
    c.initial_displacement.assign(n, 0.0);
    c.initial_velocity.assign(n, 0.0);
    c.fingers.clear();
    if (attack.strike()) {
        // The thumb: a lumped mass just off the string, moving toward the board (z only).
        FingerSpec thumb;
        thumb.key = "the thumb";
        thumb.position_m = x;
        thumb.width_m = attack.where.width_m;
        thumb.mass_kg = thumb_mass_;
        thumb.stiffness = thumb_stiffness_;
        thumb.loss = thumb_loss_;
        thumb.initial_gap_m = 1e-4;
        thumb.initial_velocity = -z_share(attack, pluck);
        c.fingers.push_back(thumb);
        return;
    }
    // Pulled toward the board, the string lies taut over the frets it meets before it is let go.
    const std::vector<double> along_z = rounded_triangle_shape(grid, x, attack.where.width_m, z_share(attack, pluck));
    std::vector<std::array<double, 2>> frets;
    for (const PointObstacle& p : c.point_obstacles) frets.push_back({p.x_m, p.height_m});
    const std::vector<double> held =
        taut_over_obstacle(grid, along_z, c.obstacle_height_m, frets, x, attack.where.width_m);
    if (polarisations == Polarisations::both && held == along_z) {
        // The whole release along its direction; the run splits it between z and y.
        const double angle = std::clamp(attack.where.angle_deg + pluck.turn_deg, -90.0, 90.0);
        c.polarisation.count = 2;
        c.polarisation.angle_deg = 90.0 + angle;
        c.polarisation.friction = fret_friction_;
        basis.to_modes(rounded_triangle_shape(grid, x, attack.where.width_m, attack.size * pluck.scale),
                       c.initial_displacement);
        return;
    }
    basis.to_modes(held, c.initial_displacement);
    rest_on_frets(c, basis, grid, c.initial_displacement);
}

const Case& NoteMaker::stopped(std::size_t fret) const {
    std::call_once(once_.at(fret), [&] {
        const double stop = neck_.fret_x(fret);
        const double sounding = neck_.length() - stop;
        std::size_t n = grid_points(sounding, grid_step_m_);
        const double fs = open_.run.sample_rate_hz;
        Case c;
        if (pinned_) {
            c = bare_;
            c.string.length_m = sounding;
            c.modes = string_modes(sounding, n);
            if (const std::size_t in_band = modes_below_nyquist(c.modes, fs); in_band < n) {
                n = std::max<std::size_t>(in_band, 2);
                c.modes = string_modes(sounding, n);
            }
        } else {
            // The string part only: the neck under the note is StringNeck's (stopped_string would
            // resample the open string's obstacle, and judge a fret far below the string to be none).
            // Every mode below fs / 2: the pinned piece's frequencies (the held string's are a few
            // cents higher: 1 % of margin) tell how many, before the held string is built.
            const ModeTable pinned = string_modes(sounding, n);
            std::size_t count = n;
            while (count > 2 && 1.01 * pinned.frequency_hz[count - 1] > 0.5 * fs) --count;
            c = held_string(bare_, stop, count);
            if (const std::size_t in_band = modes_below_nyquist(c.modes, fs); in_band < c.mode_count())
                c = held_string(bare_, stop, std::max<std::size_t>(in_band, 2));
            n = c.mode_count();
        }
        scatter(c.modes, fret);
        c.name = open_.name + "-fret" + std::to_string(fret);
        place_neck(c, neck_, fret);
        c.initial_displacement.assign(n, 0.0);
        c.initial_velocity.assign(n, 0.0);
        c.observation_points_m = {sounding - observe_from_bridge_m_};
        c.run = open_.run;
        c.fingers.clear();
        c.forces.clear();
        c.plucks.clear();
        stopped_[fret] = std::make_unique<Case>(std::move(c));
    });
    return *stopped_[fret];
}

Case NoteMaker::stand_in(std::size_t fret, const Attack& attack, const PluckVariation& pluck,
                         Polarisations polarisations) const {
    Case c = stopped(fret);
    excite(c, attack, pluck, polarisations);
    return c;
}

Case NoteMaker::fingered(std::size_t fret, const Attack& attack, const PluckVariation& pluck) const {
    Case c = open_;
    const std::size_t in_band = modes_below_nyquist(c.modes, c.run.sample_rate_hz);
    if (in_band < c.mode_count()) {  // fewer modes, a coarser grid: every mode below fs / 2
        c.modes.frequency_hz.resize(in_band);
        c.modes.sigma_per_s.resize(in_band);
        c.modes.source.resize(in_band);
        place_neck(c, neck_, 0);
        c.initial_displacement.assign(in_band, 0.0);
        c.initial_velocity.assign(in_band, 0.0);
    }
    c.name = open_.name + "-fret" + std::to_string(fret) + "-finger";
    const std::size_t n = c.mode_count();
    const double length = c.string.length_m;
    const double stop = neck_.fret_x(fret);
    const double sounding = length - stop;
    const double x = stop + pluck_position(sounding, attack, pluck);
    c.initial_displacement.assign(n, 0.0);
    c.initial_velocity.assign(n, 0.0);
    double settle = 0.0;
    if (fret > 0) {
        c.add_fret_finger(fret, "fret");
        settle = kFingerSettles;
        // The string at rest pressed on fret k: the lowest triangle on the fret's top that
        // clears every fret top (1 pm up, so round-off never puts it into a fret).
        const Grid grid{length, n};
        const auto at = [&](std::size_t k) { return c.point_obstacles.at(k - 1).x_m; };
        const auto top = [&](std::size_t k) { return c.point_obstacles.at(k - 1).height_m; };
        double apex = top(fret);
        for (std::size_t k = 1; k < fret; ++k) apex = std::max(apex, top(k) * at(fret) / at(k));
        for (std::size_t k = fret + 1; k <= neck_.fret_count(); ++k)
            apex = std::max(apex, top(k) * (length - at(fret)) / (length - at(k)));
        const ModalBasis basis(length, n);
        basis.to_modes(triangle_shape(grid, at(fret), apex + 1e-12), c.initial_displacement);
        rest_on_frets(c, basis, grid, c.initial_displacement);
    }
    // The pick: the force whose static deflection at the pluck point is the amplitude on the
    // sounding length, F = A T L' / (a (L' - a)), ramped over whole periods, then let go.
    const double a = x - stop;
    const double amplitude = z_share(attack, pluck);
    const double force = std::abs(amplitude) * c.string.tension_n * sounding / (a * (sounding - a));
    const double wave_speed = std::sqrt(c.string.tension_n / c.string.linear_density);
    const double end = settle + kPullPeriods * 2.0 * sounding / wave_speed;
    ForceSpec pick;
    pick.key = "the pick";
    pick.position_m = x;
    pick.width_m = attack.where.width_m;
    pick.direction = amplitude < 0.0 ? 1.0 : -1.0;  // toward the board, or away from it (a pop)
    pick.force_profile = {{0.0, 0.0}, {settle, 0.0}, {end, force}, {end + kRelease, 0.0}};
    c.forces = {pick};
    c.run.duration_s = open_.run.duration_s + end + kRelease;
    if (!c.fingers.empty()) c.fingers.front().force_profile = {{0.0, 0.0}, {std::min(0.005, 0.5 * c.run.duration_s), 5.0}};
    return c;
}

std::vector<double> NoteMaker::fret_positions(std::size_t fret, bool finger) const {
    std::vector<double> x;
    for (std::size_t n = fret + 1; n <= neck_.fret_count(); ++n)
        x.push_back(neck_.fret_x(n) - (finger ? 0.0 : neck_.fret_x(fret)));
    return x;
}

std::vector<std::size_t> NoteMaker::fret_numbers(std::size_t fret) const {
    std::vector<std::size_t> numbers;
    for (std::size_t n = fret + 1; n <= neck_.fret_count(); ++n) numbers.push_back(n);
    return numbers;
}

double touch_free_scale(const Case& c) {
    if (!c.fingers.empty() || !c.forces.empty() || !c.plucks.empty()) return 0.0;
    const std::size_t n = c.mode_count();
    std::vector<double> amplitude(n);
    double total = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
        const double omega = 2.0 * std::numbers::pi * c.modes.frequency_hz[j];
        const double sigma = c.modes.sigma_per_s[j];
        const double w = std::sqrt(std::max(omega * omega - sigma * sigma, 0.0));
        if (!(w > 0.0)) return 0.0;  // not an underdamped mode: no bound here
        const double q0 = c.initial_displacement[j], v0 = c.initial_velocity[j];
        amplitude[j] = std::hypot(q0, (sigma * q0 + v0) / w);
        total += amplitude[j];
    }
    const double s = c.contact_orientation();
    const double norm = std::sqrt(2.0 / c.string.length_m);
    double nearest = std::numeric_limits<double>::infinity();
    for (double g : c.obstacle_height_m)
        if (std::isfinite(g)) nearest = std::min(nearest, -s * g);
    for (const PointObstacle& p : c.point_obstacles) nearest = std::min(nearest, -s * p.height_m);
    if (!(nearest > 0.0)) return 0.0;
    if (!(total > 0.0)) return std::numeric_limits<double>::infinity();
    // A cheap first look (|phi_j| <= sqrt(2/L) everywhere), then point by point where it is not
    // enough: `shape(j)` is |phi_j| / sqrt(2/L) there.
    double scale = std::numeric_limits<double>::infinity();
    const auto tighten = [&](double clearance, auto&& shape) {
        if (clearance / (norm * total) >= scale) return;
        double bound = 0.0;
        for (std::size_t j = 0; j < n; ++j) bound += amplitude[j] * shape(j);
        if (bound > 0.0) scale = std::min(scale, clearance / (norm * bound));
    };
    // |sin((j + 1) theta)| for j = 0, 1, ... in turn, by turning a unit phasor rather than one
    // sine a mode (the grid's n^2 sines were most of this bound's cost); its round-off, under
    // 4 (j + 1) epsilon, is added so that the bound stays one.
    const auto sines = [](double theta) {
        return [turn_re = std::cos(theta), turn_im = std::sin(theta), re = 1.0, im = 0.0](std::size_t j) mutable {
            const double next = re * turn_re - im * turn_im;
            im = re * turn_im + im * turn_re;
            re = next;
            return std::abs(im) + 4.0 * static_cast<double>(j + 1) * std::numeric_limits<double>::epsilon();
        };
    };
    const double step = std::numbers::pi / static_cast<double>(n + 1);
    for (std::size_t i = 0; i < n; ++i) {
        const double g = c.obstacle_height_m[i];
        if (!std::isfinite(g)) continue;
        tighten(-s * g, sines(static_cast<double>(i + 1) * step));
    }
    // The frets at their exact positions: |phi_j(x)| / sqrt(2/L) = |sin(j pi x / L)|. This runs
    // for every pluck, so no basis (nor its transform's plan) is built for it, and a fret's
    // shapes are formed only where the cheap look does not settle it.
    for (const PointObstacle& p : c.point_obstacles)
        tighten(-s * p.height_m, sines(std::numbers::pi * p.x_m / c.string.length_m));
    return scale;
}

bool never_touches(const Case& c) { return touch_free_scale(c) > 1.0; }

std::vector<double> free_motion_at(const Case& c, double x, double interval_s, std::size_t samples) {
    const std::size_t n = c.mode_count();
    const std::vector<double> phi = ModalBasis(c.string.length_m, n).mode_shapes_at(x);
    // u(t_m) = Re sum_j a_j z_j^m, z_j = e^((-sigma_j + i w_j) interval).
    std::vector<double> are, aim, zre, zim, rre, rim;
    double total = 0.0;
    std::vector<std::complex<double>> a(n);
    for (std::size_t j = 0; j < n; ++j) {
        const double omega = 2.0 * std::numbers::pi * c.modes.frequency_hz[j];
        const double sigma = c.modes.sigma_per_s[j];
        const double w = std::sqrt(omega * omega - sigma * sigma);
        const double q0 = c.initial_displacement[j], v0 = c.initial_velocity[j];
        a[j] = phi[j] * std::complex<double>(q0, -(sigma * q0 + v0) / w);
        total += std::abs(a[j]);
    }
    for (std::size_t j = 0; j < n; ++j) {
        if (!(std::abs(a[j]) > 1e-13 * total)) continue;
        const double omega = 2.0 * std::numbers::pi * c.modes.frequency_hz[j];
        const double sigma = c.modes.sigma_per_s[j];
        const std::complex<double> r = std::exp(std::complex<double>(-sigma, std::sqrt(omega * omega - sigma * sigma)) *
                                                interval_s);
        are.push_back(a[j].real());
        aim.push_back(a[j].imag());
        zre.push_back(1.0);
        zim.push_back(0.0);
        rre.push_back(r.real());
        rim.push_back(r.imag());
    }
    std::vector<double> u(samples);
    const std::size_t kept = are.size();
    for (std::size_t m = 0; m < samples; ++m) {
        double sum = 0.0;
        for (std::size_t j = 0; j < kept; ++j) {
            sum += are[j] * zre[j] - aim[j] * zim[j];
            const double re = zre[j] * rre[j] - zim[j] * rim[j];
            zim[j] = zre[j] * rim[j] + zim[j] * rre[j];
            zre[j] = re;
        }
        u[m] = sum;
    }
    return u;
}

}  // namespace fretbuzz
