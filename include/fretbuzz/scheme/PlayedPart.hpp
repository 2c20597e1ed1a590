#pragma once
// What acts on the string from outside at a pad of grid points: a finger (Finger), a force
// gesture (ForceProfile), a plucker (Pluck). The Stepper solves each on-string part's pad
// every step with the string's free prediction there, and counts its energy, work and loss
// in the balance H - work + dissipated = constant. Heights and forces are in the solve's
// orientation (the fretboard below).
#include <cstddef>
#include <span>
#include <vector>

namespace fretbuzz {

class PlayedPart {
public:
    virtual ~PlayedPart() = default;

    // Grid points of the pad, in increasing order.
    virtual const std::vector<std::size_t>& pad() const = 0;
    // Levels n-1 (u0) and n (u1) of the string at the pad points (pad order).
    virtual void start(std::span<const double> u0, std::span<const double> u1) = 0;
    // Step n -> n + 1 from the pad points' free predictions (pad order): writes the total force
    // per unit length at each pad point (the part's and the obstacle's) into `force` and
    // returns sum_i Psi_obstacle(eta_i^{n+1}) over the pad.
    virtual double step(long n, std::span<const double> predicted, std::span<double> force) = 0;
    // u^n and u^{n-1} at the pad points after the last step (pad order).
    virtual std::span<const double> current() const = 0;
    virtual std::span<const double> previous() const = 0;
    // Reads the obstacle at the pad again (after its heights changed).
    virtual void read_obstacle(const std::vector<double>& obstacle) = 0;
    // True once the part has left the string for good (its pad goes back to the obstacle's solve).
    virtual bool left() const { return false; }

    virtual double energy() const { return 0.0; }  // its own kinetic and contact energy, (n-1, n)
    virtual double work() const = 0;                // done on the string so far
    virtual double loss() const { return 0.0; }     // its contact loss so far (>= 0)
    // Force per unit length pressing pad point p on the obstacle that friction along y acts
    // with (a finger holds the string there; gestures and pluckers drag nothing sideways).
    virtual double rubbing_force(std::size_t) const { return 0.0; }
    // Height of the part's body (solve orientation), NaN where it has none on the string.
    virtual double body_height() const = 0;

    virtual int max_iterations() const = 0;
    // In the last step: whether the obstacle pushed on a pad point, and whether the part acted.
    virtual bool touched_obstacle() const = 0;
    virtual bool acted() const = 0;

protected:
    PlayedPart() = default;
    PlayedPart(const PlayedPart&) = default;
    PlayedPart& operator=(const PlayedPart&) = default;
};

}  // namespace fretbuzz
