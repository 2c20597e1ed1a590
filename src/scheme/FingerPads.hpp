#pragma once
// The fingers on the string as PointContact's joint solve sees them (GridPads): their pads one
// after the other, each finger's trial from its pad's predictions raised by the points' push.
#include <cstddef>
#include <span>
#include <vector>

#include "fretbuzz/scheme/PlayedParts.hpp"
#include "fretbuzz/scheme/PointContact.hpp"

namespace fretbuzz {

class FingerPads final : public GridPads {
public:
    FingerPads(PlayedParts& parts, std::span<const std::size_t> points, std::span<const double> w, std::vector<double>& trial)
        : parts_(parts), points_(points), w_(w), trial_(trial) {
        each([&](Finger&, std::size_t, std::size_t, std::size_t) { ++count_; });
    }
    std::span<const std::size_t> points() const override { return points_; }
    std::size_t heights() const override { return count_; }
    std::size_t end(std::size_t f) const override {
        std::size_t last = 0;
        each([&](Finger&, std::size_t k, std::size_t at, std::size_t n) {
            if (k == f) last = at + n;
        });
        return last;
    }
    void solve(std::span<const double> shift, std::span<double> force, std::span<double> height, std::span<double> residual,
               std::span<double> size) override {
        raise(shift);
        each([&](Finger& f, std::size_t k, std::size_t at, std::size_t n) {
            f.trial(std::span<const double>(trial_).subspan(at, n), force.subspan(at, n));
            height[k] = f.height_step();
            residual[k] = f.residual();
            size[k] = f.residual_size();
        });
    }
    void guess(std::span<double> height) const override {
        each([&](Finger& f, std::size_t k, std::size_t, std::size_t) { height[k] = f.height_guess(); });
    }
    void trial(std::span<const double> shift, std::span<const double> height, std::span<double> force,
               std::span<double> residual, std::span<double> size) override {
        raise(shift);
        each([&](Finger& f, std::size_t k, std::size_t at, std::size_t n) {
            f.trial_at(std::span<const double>(trial_).subspan(at, n), height[k], force.subspan(at, n));
            residual[k] = f.residual();
            size[k] = f.residual_size();
        });
    }
    void slopes(std::span<double> response, std::span<double> lift, std::span<double> pull,
                std::span<double> slope) const override {
        each([&](Finger& f, std::size_t k, std::size_t at, std::size_t n) {
            for (std::size_t p = 0; p < n; ++p) {
                response[at + p] = f.response(p);
                lift[at + p] = f.lift(p);
                pull[at + p] = f.pull() * f.lift(p);
            }
            slope[k] = f.residual_slope();
        });
    }

    // f(finger, its index among those on, where its points start, how many).
    template <class F>
    void each(F&& f) const {
        std::size_t at = 0, index = 0;
        for (std::size_t k = 0; k < parts_.fingers().size(); ++k) {
            if (!parts_.on(k)) continue;
            Finger& finger = parts_.finger(k);
            f(finger, index++, at, finger.pad().size());
            at += finger.pad().size();
        }
    }

private:
    void raise(std::span<const double> shift) {
        trial_.resize(w_.size());  // (within the reserved capacity)
        for (std::size_t r = 0; r < w_.size(); ++r) trial_[r] = w_[r] + shift[r];
    }
    PlayedParts& parts_;
    std::span<const std::size_t> points_;
    std::span<const double> w_;
    std::vector<double>& trial_;
    std::size_t count_ = 0;
};

}  // namespace fretbuzz
