// Two independent implementations of eq. (4): the literal dense-matrix transcription (D and
// D~ as full N x N matrices, contact solved everywhere, in space) and the modal Stepper
// (sine transforms, scheduled contact checks, difference form). Through fret contacts they
// must give the same string motion, up to the round-off the dense form accumulates.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "fretbuzz/geometry/InitialShape.hpp"
#include "fretbuzz/geometry/ObstacleProfile.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/CsvTable.hpp"
#include "fretbuzz/input/BuiltinFiles.hpp"
#include "fretbuzz/scheme/DenseMatrixScheme.hpp"
#include "fretbuzz/numerics/ModalBasis.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/Stepper.hpp"

namespace fretbuzz {
namespace {

// The bass-pop string with its first 150 modes, over its neck profile resampled on the
// coarser grid, plucked 3 mm at 0.637 m: it hits frets within a few milliseconds.
Case coarse_bass() {
    const Case bass = load_case("bass-pop");
    Case c = bass;
    const std::size_t modes = 150;
    c.modes.frequency_hz.resize(modes);
    c.modes.sigma_per_s.resize(modes);
    c.modes.source.resize(modes);
    const Grid fine{bass.string.length_m, bass.mode_count()}, coarse{bass.string.length_m, modes};
    std::vector<double> x(fine.points);
    for (std::size_t i = 0; i < fine.points; ++i) x[i] = fine.x(i);
    std::vector<double> padded_x{0.0}, padded_g{bass.obstacle_height_m.front()};
    padded_x.insert(padded_x.end(), x.begin(), x.end());
    padded_g.insert(padded_g.end(), bass.obstacle_height_m.begin(), bass.obstacle_height_m.end());
    c.obstacle_height_m = sample_profile_on_grid(padded_x, padded_g, coarse, "bass neck");
    const std::vector<double> shape = triangle_shape(coarse, 0.637, 3e-3);
    const ModalBasis basis(c.string.length_m, modes);
    c.initial_displacement.resize(modes);
    basis.to_modes(shape, c.initial_displacement);
    c.initial_velocity.assign(modes, 0.0);
    return c;
}

TEST(DenseAgreement, DenseTranscriptionAndModalStepperAgreeThroughContacts) {
    const Case c = coarse_bass();
    const double dt = 1.0 / 200000.0;
    const Plan plan(c, dt);
    Stepper modal(plan, c.initial_displacement, c.initial_velocity);
    DenseMatrixScheme dense(c, dt);
    modal.step();  // both now hold u^1
    const double x = 0.854;
    const std::vector<double> phi = plan.basis().mode_shapes_at(x);
    double worst = 0.0, peak = 0.0;
    for (long n = 2; n <= 3000; ++n) {  // 15 ms
        modal.step();
        dense.step();
        if (n % 25 != 0) continue;
        const double u_modal = modal.displacement(phi), u_dense = dense.displacement_at(x);
        worst = std::max(worst, std::abs(u_modal - u_dense));
        peak = std::max(peak, std::abs(u_dense));
        // The whole string, not just one point:
        const std::vector<double> u_grid = plan.basis().displacement_at_grid(modal.modal_displacement());
        for (std::size_t i = 0; i < u_grid.size(); ++i)
            ASSERT_NEAR(u_grid[i], dense.displacement()[i], 1e-9 * 3e-3) << "step " << n << " point " << i;
    }
    EXPECT_GT(modal.statistics().contact_steps, 20);
    EXPECT_LT(worst / peak, 1e-9);
}

}  // namespace
}  // namespace fretbuzz
