// A built-in case edited in code: the paper's bass 'pop' (fretbuzz::load_case("bass-pop"))
// run for 20 ms at three contact stiffnesses K, printing for each the steps with contact,
// the largest energy held by the contact and the largest relative energy increase (the
// scheme's energy never grows, whatever K).
#include <cmath>
#include <cstdio>

#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/run/ResultRecorder.hpp"
#include "fretbuzz/run/Simulation.hpp"

int main() {
    bool ok = true;
    for (const double k : {1e11, 1e12, 1e13}) {
        fretbuzz::Case c = fretbuzz::load_case("bass-pop");
        c.contact.stiffness = k;
        c.run.duration_s = 0.02;
        fretbuzz::ResultRecorder recorder;
        fretbuzz::RunObserver* observers[] = {&recorder};
        const fretbuzz::RunSummary s = fretbuzz::simulate(c, observers);
        double held = 0.0;
        for (const double e : recorder.run().contact_energy) held = std::fmax(held, e);
        std::printf("K = %.0e: %ld steps with contact, contact energy up to %.3e J, energy increase at most %.1e\n", k,
                    s.contact_steps, held, s.max_relative_energy_increase);
        ok = ok && s.contact_steps > 0 && s.max_relative_energy_increase < 1e-12;
    }
    return ok ? 0 : 1;
}
