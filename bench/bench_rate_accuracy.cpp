// fretbuzz_rate_accuracy: how far the real-time engine's sound at oversampling M departs from
// the same voice at a finer rate (the reference), per preset: log-spectral distance (dB) over
// 1/6-octave bands and the relative error of the spectral centroid, over the first 0.5 s
// after one strike at 48 kHz (see RateAccuracy.hpp). The last column compares the reference
// itself with twice its rate: the error left in the reference.
#include <cstdio>
#include <vector>

#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/StoppedString.hpp"
#include "fretbuzz/realtime/RateAccuracy.hpp"

int main() {
    using namespace fretbuzz;
    struct Voice {
        const char* name;
        int fret;
        double strike_at;  // fraction of the sounding length
    };
    const Voice voices[] = {{"tanpura", 0, 0.3}, {"sitar", 0, 0.3}, {"bass-pluck", 5, 0.8}, {"guitar-point", 0, 0.8},
                            {"guitar-point", 3, 0.8}};
    constexpr int kReference = 8;
    std::printf("%-16s %4s  %-28s  %s\n", "voice", "fret", "M: modes, distance dB, centroid error",
                "reference M=8 vs M=16");
    for (const Voice& v : voices) {
        const Case open = load_case(v.name);
        const Case c = v.fret == 0 ? open : stopped_string(open, fret_stop_m(open, v.fret), open.mode_count());
        const Strike strike{v.strike_at * c.string.length_m, 1.0, 0.01, false};
        std::printf("%-16s %4d ", v.name, v.fret);
        for (int m = 1; m < kReference; ++m) {
            const RateError e = rate_error(c, strike, m, kReference);
            std::printf(" %d:%3zu %5.2f %5.3f |", m, e.modes, e.distance_db, e.centroid_error);
        }
        const RateError r = rate_error(c, strike, kReference, 2 * kReference);
        std::printf(" %6.2f %6.4f\n", r.distance_db, r.centroid_error);
        std::fflush(stdout);
    }
    return 0;
}
