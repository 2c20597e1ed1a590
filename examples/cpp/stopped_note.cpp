// The partials of a stopped note: the string held down on fret k (fretbuzz::stopped_string,
// the stand-in for a fretted note in set-up studies and real-time voices) against the same
// piece pinned at the fret. The stiff string is partly clamped over the fret, so it sounds a
// few cents sharp of the pinned piece.
//   stopped_note [CASE [FRET ...]]   (default: bass-neck 1 5 12 15)
// The stop is the case's own fret k where its obstacle has frets (where `fret = k` presses the
// string), else x_k = L (1 - 2^(-k/12)); the finger is stopping_finger()'s there (`fret = k`'s,
// the string on fret k - 1 too). Prints CSV: case, fret, stop_m, partial, pinned_hz, held_hz,
// held_sigma_per_s, cents (held over pinned), for the first 10 partials, and the finger:
// behind_m (the fret behind the stop the string lies on; 0: none), pad_centre_m, pad_width_m.
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/StoppedString.hpp"
#include "fretbuzz/scheme/HeldString.hpp"

int main(int argc, char** argv) {
    try {
        const std::string name = argc > 1 ? argv[1] : "bass-neck";
        std::vector<int> frets;
        for (int i = 2; i < argc; ++i) frets.push_back(std::stoi(argv[i]));
        if (frets.empty()) frets = {1, 5, 12, 15};
        const fretbuzz::Case open = fretbuzz::load_case(name);
        const double length = open.string.length_m;
        std::printf("case,fret,stop_m,partial,pinned_hz,held_hz,held_sigma_per_s,cents,behind_m,pad_centre_m,pad_width_m\n");
        bool sharp = true;
        for (const int k : frets) {
            const auto index = static_cast<std::size_t>(k - 1);
            const double stop = index < open.fret_positions_m.size() ? open.fret_positions_m[index] : fretbuzz::fret_position(length, k);
            const fretbuzz::HeldString::Finger finger = fretbuzz::stopping_finger(open, stop);
            const fretbuzz::Case stopped = fretbuzz::stopped_string(open, stop, open.mode_count(), finger);
            const fretbuzz::ModeTable pinned = fretbuzz::HeldString(open.modes, length, stop).pinned_partials(10);
            for (std::size_t n = 0; n < 10; ++n) {
                const double held = stopped.modes.frequency_hz[n];
                const double cents = 1200.0 * std::log2(held / pinned.frequency_hz[n]);
                std::printf("%s,%d,%.6f,%zu,%.6f,%.6f,%.6f,%.4f,%.6f,%.6f,%.6f\n", name.c_str(), k, stop, n + 1,
                            pinned.frequency_hz[n], held, stopped.modes.sigma_per_s[n], cents, finger.behind_m, finger.pad_centre_m,
                            finger.pad_width_m);
                sharp = sharp && cents > -0.5;
            }
        }
        return sharp ? 0 : 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "stopped_note: %s\n", e.what());
        return 2;
    }
}
