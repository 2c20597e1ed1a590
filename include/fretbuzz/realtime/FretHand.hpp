#pragma once
// The fretting hand of a real-time voice on one string with frets: the library's Finger (the
// finger `fret = k` puts on the string offline), given to the string before it is planned,
// lifted after its first step, then placed just behind fret k and pressed at run time (a
// note), and ramped off and taken away again (the open string rings). Used by the one-string
// Engine and by each fretted string of a BridgeEngine. Allocates nothing once prepared.
#include <array>
#include <cstddef>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/VibratingString.hpp"

namespace fretbuzz {

class FretHand {
public:
    // Adds the finger to c (before c is planned) if c has frets: its pad for every fret is
    // known now and the finger is as wide as the widest, so moving it allocates nothing.
    void add_to(Case& c, double internal_rate_hz);
    // Builds the rows of S of every pad it may take (a row is built the first time it is used).
    void prepare_rows(Plan& plan, const Case& c) const;

    bool present() const { return finger_ != kNone; }
    int fret_count() const { return static_cast<int>(pads_.size()); }
    int fret() const { return fret_; }  // the fret pressed; 0: none (open, or lifting)
    bool on(const VibratingString& s) const { return present() && s.finger_on(finger_); }

    // Lands the finger behind fret k (1 <= k <= fret_count()) and ramps its force up; the
    // caller counts the energy the landing changes. False if it could not be placed.
    bool down(VibratingString& s, int k);
    // Ramps its force down (changes no energy now); retire() takes it off once it has left.
    void up(VibratingString& s);
    // Once lifted and its force gone, whether it has left the string (then call take_off,
    // counting the energy its motion takes with it).
    bool ready_to_retire(const VibratingString& s) const;
    // Off the string at once (after the first step, a silence, or once it has left).
    void take_off(VibratingString& s);

private:
    static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
    std::size_t finger_ = kNone;             // its index among the string's fingers
    std::vector<std::array<double, 2>> pads_;  // per fret: pad centre and width (m)
    double force_ = 0.0;                     // N, once pressed
    long ramp_steps_ = 1;                    // steps to press it or to let it go
    int fret_ = 0;
    bool lifting_ = false;
    long lifted_at_ = 0;  // the step its force reaches zero
};

}  // namespace fretbuzz
