#pragma once
// A string held down at one point x_h (pressed onto a fret's top by a finger behind it): the
// open string's modal model (its nu_j and sigma_j as the case gives them, measured or modelled,
// on the sine modes phi_j(x) = sqrt(2 / L) sin(j pi x / L)) with u(x_h) = 0 imposed, the
// string going on over the fret to the nut. A flexible string would then sound as the piece
// from x_h to the bridge pinned at x_h; a stiff one is partly clamped there (its slope is
// continuous over the fret and the near side resists it), and its partials lie between those
// of the pinned piece and those of the piece clamped at x_h, higher by about sqrt(B') / pi
// (one clamped end of Fletcher's stiff string; B' the shortened piece's inharmonicity).
//
// The held modes. The constrained problem (K - omega^2) a = lambda z, z^T a = 0 with
// K = diag(omega_j^2) and z_j = phi_j(x_h) reduces to its secular equation
//   R + sum_j z_j^2 / (omega_j^2 - omega^2) = 0,
// one root between each two consecutive open modes (they are the eigenvalues of K projected
// onto the null space of z^T; the tests check them against that dense eigenproblem solved by
// Eigen), with the eigenvector a_j = z_j / (omega_j^2 - omega^2). R is the static compliance
// of the modes above the table, from the dispersion extrapolated past it (StringDispersion):
// without it a flexible string's held modes converge as 1 / N (0.27 cents at fret 5 with 862
// modes). Open modes with z_j = 0 (a node at x_h) stay modes of the held string.
//
// The sounding side. Each held mode has a share of its kinetic energy on the near side
// [0, x_h] (summed on the open string's grid). Where a mode of the far side [x_h, L] and one
// of the near side have nearly the same frequency they mix (at fret 12 of a uniform string
// every pair mixes half and half, into a pinned-like and a clamped-like mode). The finger
// (Finger below) undoes the mixing and adds its own loss: it is the finger model of
// scheme/Finger.hpp at rest, linearised. Pressed with F, each of its p pad points is
// compressed by eta = (F / K_f)^(1 / alpha) and tied to the finger's mass M by a spring
// alpha K_f eta^(alpha - 1) / p and a damper lambda F / p (its Hunt-Crossley loss at that
// compression); the string lies on fret k - 1 too (a second point held, u(x_b) = 0: the
// finger between the frets presses it onto both). Nothing is fitted: the partials' dampings
// are the string's own plus what the pad's dampers take, through the mass that moves with
// the string at low frequencies (so little loss there) and stands still at high ones.
// Each sounding partial is, among the complex modes of a window of held modes around it with
// the finger and the fret behind attached (the other held modes as their receptance at those
// points, the held modes never computed and the modes above the table as their static
// flexibility), the one with most of its energy on the far side nearest to the pinned piece's
// partial times the last held-to-pinned ratio: picked by Eigen's QZ with the receptance at
// the target frequency, then refined by inverse iteration with the receptance at the
// eigenvalue itself (the root of the exact problem: a dense eigenproblem of every mode agrees
// to 0.05 cents). The first 40 partials are solved, then one every 5 % in partial number,
// the ratio and the finger's share of the damping interpolated between. On the jazz-bass E
// string at frets 5, 12 and 15 this is the finger model's run (`fret = k`) within 0.73 cents
// and 14 % in damping on partials 1 to 10 (docs/validation.md, section 7).
// Partials above half the open table's highest frequency (where the table's truncation starts
// to move the held modes by a few hundredths of a cent) follow the pinned piece's dispersion,
// scaled by the held-to-pinned ratio of the last partial solved, and its damping plus the
// finger's share of that last partial.
#include <cstddef>
#include <utility>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/model/ModeTable.hpp"
#include "fretbuzz/model/StringDispersion.hpp"

namespace fretbuzz {

class HeldString {
public:
    static constexpr std::size_t kWindowHalfWidth = 3;  // held modes on each side of a partial

    // The finger that holds the string down (see above), on the open string's grid.
    struct Finger {
        double pad_centre_m = 0.0;  // in (behind_m, x_h)
        double pad_width_m = 0.0;   // its points: the open grid's within width / 2 of the centre
        double mass_kg = 0.0;       // M
        double stiffness = 0.0;     // K_f of the whole pad, N/m^alpha
        double exponent = 1.0;      // alpha >= 1
        double loss = 0.0;          // lambda, s/m
        double force_n = 0.0;       // F, pressing it toward the fretboard
        double behind_m = 0.0;      // the fret behind x_h the string lies on too (0: none)

        // The finger of `spec` (its pad, mass and contact law) pressing with force_n.
        static Finger of(const FingerSpec& spec, double force_n, double behind_m);
    };

    struct Mode {
        double frequency_hz = 0.0;
        double sigma_per_s = 0.0;  // the open dampings weighted by the mode's a_j^2
        double near_share = 0.0;   // kinetic energy on [0, x_h] over the whole
    };

    // open: the mode table of the string pinned at 0 and length_m. Throws InputError unless
    // 0 < held_at_m < length_m and the table has at least two modes.
    HeldString(const ModeTable& open, double length_m, double held_at_m);

    // The held modes (no damping added), ascending in frequency, up to a few above
    // trusted_below_hz().
    const std::vector<Mode>& modes() const { return modes_; }
    // The first `count` partials of the sounding side [x_h, L] with the finger on the near side
    // (above), on a string of that linear density (kg/m). InputError unless the finger's pad
    // lies between behind_m and x_h and its parameters are positive (its loss at least 0).
    ModeTable sounding_partials(std::size_t count, const Finger& finger, double linear_density) const;
    // The piece from x_h to L pinned at both ends: the open string's dispersion at n pi / (L - x_h).
    ModeTable pinned_partials(std::size_t count) const;
    // Up to this frequency the held modes are computed; above, extrapolated (see above).
    double trusted_below_hz() const { return trusted_below_hz_; }
    // R: the static compliance at x_h of the modes above the table (m / N per unit mass).
    // The secular equation is that of the open modes with a spring of stiffness 1 / R at x_h.
    double static_compliance() const { return static_compliance_; }

private:
    // A held mode: a root of the secular equation, kept as an offset from the pole of an open
    // mode group (precise where the root lies close to that pole), or a vector of open modes
    // left as it was (deflated: no weight at x_h, or a repeated open frequency).
    struct Root {
        double squared_omega = 0.0;
        std::size_t origin = 0;  // group the offset is taken from
        double offset = 0.0;
        std::vector<std::pair<std::size_t, double>> deflated;  // (open mode, coefficient), if any
    };
    // Open modes of (nearly) the same frequency act as one pole of the secular equation.
    struct Group {
        double squared_omega = 0.0;
        double weight = 0.0;  // sum of z_j^2
        std::vector<std::size_t> members;
        bool active = false;  // a pole of the secular equation (else its members have a node at x_h)
    };

    void find_roots(double trusted_squared_omega);
    std::vector<double> coefficients(const Root& r) const;

    double length_m_, held_at_m_;
    StringDispersion dispersion_;
    std::vector<double> z_;  // phi_j(x_h)
    std::vector<Group> groups_;
    std::vector<std::size_t> group_of_;  // open mode -> its group
    std::vector<Root> roots_;            // ascending
    std::vector<Mode> modes_;
    // Each held mode's overlaps with the next 2 w, on the near side and through the open dampings.
    std::vector<std::vector<double>> near_band_, damping_band_;
    double trusted_below_hz_ = 0.0;
    double static_compliance_ = 0.0;
};

}  // namespace fretbuzz
