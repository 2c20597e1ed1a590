#include "fretbuzz/setup/Attack.hpp"

#include <cstdint>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/InstrumentUnits.hpp"

namespace fretbuzz {

namespace {

// SplitMix64 (Steele, Lea, Flood 2014): a counter-based generator whose output depends only
// on its input, the same with every compiler and library (std:: distributions are not).
std::uint64_t mix(std::uint64_t z) {
    z += 0x9e3779b97f4a7c15ULL;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

// A number in [-1, 1) for the given coordinates.
double jitter(std::uint64_t seed, std::uint64_t a, std::uint64_t b, std::uint64_t c, std::uint64_t d) {
    const std::uint64_t h = mix(mix(mix(mix(mix(seed) ^ a) ^ b) ^ c) ^ d);
    return 2.0 * static_cast<double>(h >> 11) / 9007199254740992.0 - 1.0;  // 53 bits
}

}  // namespace

const char* gesture_name(Gesture gesture) {
    switch (gesture) {
        case Gesture::finger: return "finger";
        case Gesture::pick: return "pick";
        case Gesture::pop: return "pop";
        case Gesture::slap: return "slap";
    }
    return "";
}

std::vector<Attack> parse_attacks(const std::string& list, const AttackSettings& s, const std::string& option) {
    const std::string allowed = "soft, medium, hard, pick, pop, slap, a finger pluck's amplitude in (0, 10] mm "
                                "(e.g. 1.2mm) or a slap's speed in (0, 10] m/s (e.g. 3m/s), separated by commas "
                                "(e.g. soft,medium,hard)";
    std::vector<Attack> attacks;
    std::size_t start = 0;
    while (start <= list.size()) {
        const std::size_t comma = list.find(',', start);
        const std::string word = list.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
        start = comma == std::string::npos ? list.size() + 1 : comma + 1;
        Attack a;
        a.label = word;
        a.where = s.finger;
        if (word == "soft") {
            a.size = s.soft_m;
        } else if (word == "medium") {
            a.size = s.medium_m;
        } else if (word == "hard") {
            a.size = s.hard_m;
        } else if (word == "pick") {
            a.gesture = Gesture::pick;
            a.size = s.pick_m;
            a.where = s.pick;
        } else if (word == "pop") {
            a.gesture = Gesture::pop;
            a.size = s.pop_m;
            a.where = s.pop;
        } else if (word == "slap") {
            a.gesture = Gesture::slap;
            a.size = s.slap_m_per_s;
            a.where = s.slap;
        } else if (word.ends_with("m/s")) {
            double speed = 0.0;
            try {
                speed = parse_quantity(word.substr(0, word.size() - 3) + " m/s", Quantity::velocity, option);
            } catch (const InputError&) {
                throw InputError(option + " " + list + ": \"" + word + "\" is not an attack; give " + allowed);
            }
            if (!(speed > 0.0 && speed <= 10.0))
                throw InputError(option + " " + list + ": \"" + word + "\" is out of range; give " + allowed);
            a.gesture = Gesture::slap;
            a.size = speed;
            a.where = s.slap;
        } else {
            double amplitude = 0.0;
            try {
                amplitude = parse_quantity_or(word, Quantity::length, "mm", option);
            } catch (const InputError&) {
                throw InputError(option + " " + list + ": \"" + word + "\" is not an attack; give " + allowed);
            }
            if (!(amplitude > 0.0 && amplitude <= 10e-3))
                throw InputError(option + " " + list + ": \"" + word + "\" is out of range; give " + allowed);
            a.size = amplitude;
        }
        for (const Attack& other : attacks)
            if (other.label == a.label) throw InputError(option + " " + list + ": \"" + word + "\" is listed twice");
        attacks.push_back(a);
    }
    if (attacks.size() > 8) throw InputError(option + " " + list + ": at most 8 attacks at once");
    return attacks;
}

std::vector<PluckVariation> ensemble(const AttackSettings& s, std::size_t string, std::size_t fret, std::size_t count) {
    std::vector<PluckVariation> members(count);
    for (std::size_t m = 1; m < members.size(); ++m) {
        members[m].shift_m = s.position_spread_m * jitter(s.seed, 1, string, fret, m);
        members[m].scale = 1.0 + s.strength_spread * jitter(s.seed, 2, string, fret, m);
        members[m].turn_deg = s.angle_spread_deg * jitter(s.seed, 3, string, fret, m);
    }
    return members;
}

}  // namespace fretbuzz
