// Runs a built-in case for a few milliseconds through the installed library and checks
// the discrete energy balance: the energy plus what damping removed stays constant.
#include <cmath>
#include <cstdio>

#include "fretbuzz/Version.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/run/ResultRecorder.hpp"
#include "fretbuzz/run/Simulation.hpp"

int main() {
    fretbuzz::Case c = fretbuzz::load_case("guitar-point");
    c.run.sample_rate_hz = 200000.0;
    c.run.duration_s = 0.005;
    c.run.allow_aliasing = true;  // a coarse, fast rate: the energy balance holds even where modes alias
    fretbuzz::ResultRecorder recorder;
    fretbuzz::RunObserver* observers[] = {&recorder};
    const fretbuzz::RunSummary summary = fretbuzz::simulate(c, observers);
    const fretbuzz::RecordedRun& r = recorder.run();
    double worst = 0.0;
    for (std::size_t i = 0; i < r.energy.size(); ++i)
        worst = std::fmax(worst, std::fabs(r.energy[i] + r.dissipated[i] - r.energy.front() - r.dissipated.front()));
    const double relative = worst / r.energy.front();
    std::printf("fretbuzz %.*s: %zu steps, %zu samples, energy balance %.2e\n", static_cast<int>(fretbuzz::version.size()),
                fretbuzz::version.data(), static_cast<std::size_t>(summary.steps), r.time.size(), relative);
    return r.time.size() > 1 && relative < 1e-10 ? 0 : 1;
}
