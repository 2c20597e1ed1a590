#pragma once
// What a string's steps did, as its parts tell it: counts over the run (StepStatistics) and the
// flags of the step being taken that more than one part reads.
#include <algorithm>

namespace fretbuzz {

struct StepStatistics {
    long contact_steps = 0;            // steps with a non-zero obstacle contact force somewhere
    long played_steps = 0;             // steps where a finger, plucker or force gesture acted on the string
    int max_newton_iterations = 0;
    double points_solved = 0;          // sum over steps of the points solved
    long free_flight_steps = 0;        // steps jumped over by FreeFlight
    long joint_steps = 0;              // steps whose exact points and grid points were solved together
};

struct StepRecord {
    StepStatistics stats;
    // The step loads the modes explicitly (a force gesture, an exact plucker's push): its impulse
    // then goes through one vector, and the step counts once as played.
    bool loaded = false;
    bool touched_obstacle = false;  // the obstacle pushed on the string somewhere in the step

    void mark_loaded() {
        if (!loaded) ++stats.played_steps;
        loaded = true;
    }
    // A finger or plucker acted in the step (a loaded step is counted already).
    void played_by_parts(bool acted) {
        if (acted && !loaded) ++stats.played_steps;
    }
    void iterations(int count) { stats.max_newton_iterations = std::max(stats.max_newton_iterations, count); }
};

}  // namespace fretbuzz
