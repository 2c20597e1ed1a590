#pragma once
// The parts playing a string at pads (the case's fingers and pluckers, in that order) as one
// collection of PlayedPart, each with whether it is on the string (a finger lifted, a plucker
// gone: off), and the grid points their pads hold: a point under a pad is solved with its part,
// never by the obstacle's own solve, and never asleep. Finger f is part f. A copy links to its
// own parts.
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "fretbuzz/scheme/Finger.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/PlayedPart.hpp"
#include "fretbuzz/scheme/Pluck.hpp"

namespace fretbuzz {

class PlayedParts {
public:
    // The plan's fingers and pluckers (at their exact positions), their pads claimed
    // (InputError if two overlap).
    explicit PlayedParts(const Plan& plan);
    PlayedParts(const PlayedParts& other);
    PlayedParts(PlayedParts&& other) noexcept = default;  // (the parts stay where they are)
    PlayedParts& operator=(const PlayedParts&) = delete;
    PlayedParts& operator=(PlayedParts&&) = delete;

    std::size_t size() const { return parts_.size(); }
    bool empty() const { return parts_.empty(); }
    PlayedPart& operator[](std::size_t k) { return *parts_[k]; }
    const PlayedPart& operator[](std::size_t k) const { return *parts_[k]; }
    bool on(std::size_t k) const { return on_[k] != 0; }
    void set_on(std::size_t k, bool on) { on_[k] = on ? 1 : 0; }
    // f(part) for every part on the string.
    template <class F>
    void each_on(F&& f) {
        for (std::size_t k = 0; k < parts_.size(); ++k)
            if (on_[k] != 0) f(*parts_[k]);
    }
    template <class F>
    void each_on(F&& f) const {
        for (std::size_t k = 0; k < parts_.size(); ++k)
            if (on_[k] != 0) f(static_cast<const PlayedPart&>(*parts_[k]));
    }

    const std::vector<Finger>& fingers() const { return fingers_; }
    Finger& finger(std::size_t f) { return fingers_.at(f); }
    const std::vector<Pluck>& plucks() const { return plucks_; }
    bool fingers_on() const;

    // The grid points held by pads (on_pad()[i] != 0) and how many.
    std::span<const char> on_pad() const { return on_pad_; }
    bool on_pad(std::size_t i) const { return on_pad_[i] != 0; }
    std::size_t pad_points() const { return pad_points_; }
    // Holds `pad` for a part (false, nothing held, if another part holds one of its points).
    bool hold(const std::vector<std::size_t>& pad);
    void release(const std::vector<std::size_t>& pad);
    // The sums of every part's energy, work and loss, on the string or not (a lifted finger's and
    // a gone plucker's so far still count).
    double energy() const;
    double work() const;
    double loss() const;

private:
    void link();
    void claim(const std::vector<std::size_t>& pad, const std::string& key, const ModalBasis& basis);

    std::vector<Finger> fingers_;
    std::vector<Pluck> plucks_;
    std::vector<PlayedPart*> parts_;
    std::vector<char> on_;
    std::vector<char> on_pad_;  // grid points under a part's pad
    std::size_t pad_points_ = 0;
};

}  // namespace fretbuzz
