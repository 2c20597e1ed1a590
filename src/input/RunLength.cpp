#include "fretbuzz/input/RunLength.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace fretbuzz {

namespace {

void cut(std::vector<std::array<double, 2>>& profile, double end) {
    const auto last = std::find_if(profile.begin(), profile.end(), [end](const auto& p) { return p[0] >= end; });
    if (last != profile.end()) profile.erase(last + 1, profile.end());
}

}  // namespace

void set_duration(Case& c, double duration_s) {
    c.run.duration_s = duration_s;
    if (!(std::isfinite(duration_s) && duration_s > 0.0)) return;
    for (FingerSpec& f : c.fingers) cut(f.force_profile, duration_s);
    for (ForceSpec& f : c.forces) cut(f.force_profile, duration_s);
    std::erase_if(c.plucks, [&](const PluckSpec& p) {
        if (!(p.start_s > duration_s)) return false;
        std::ostringstream why;
        why << p.key << " (a " << (p.pop ? "pop" : "pluck") << " at " << p.start_s
            << " s) is left out: it starts after the run's end at " << duration_s << " s";
        c.warnings.push_back(why.str());
        return true;
    });
}

void set_duration(StringsCase& sc, double duration_s) {
    sc.run.duration_s = duration_s;
    for (Case& c : sc.strings) set_duration(c, duration_s);
}

}  // namespace fretbuzz
