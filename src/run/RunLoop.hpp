#pragma once
// One run from start to finish: steps the string (or flies it freely over output
// intervals where no contact is possible) and hands every signal its observers asked for
// to them, at the steps they asked for. Used by simulate().
#include <chrono>
#include <cmath>
#include <optional>
#include <span>
#include <vector>

#include "AudioBand.hpp"
#include "AudioStreams.hpp"
#include "EnergyAudit.hpp"
#include "PerStepQueue.hpp"
#include "SnapshotTaps.hpp"
#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/scheme/FreeFlight.hpp"
#include "fretbuzz/scheme/Stepper.hpp"

namespace fretbuzz {

// What a run of the case lays out for its observers, and its summary's opening fields (both
// laws' runs).
RunLayout layout_of(const Case& c);
RunSummary summary_of(const Case& c, const Plan& plan, const RunLayout& layout);

class RunLoop {
public:
    RunLoop(const Case& c, std::span<RunObserver* const> observers, const RunOptions& options);
    RunSummary run();

private:
    using Clock = std::chrono::steady_clock;
    void connect_observers();
    void plan_free_flight();
    long fly();  // steps flown (0: none)
    void after_step();
    // Whether step n_ has an output row (every step at an audio rate: no integer division then).
    bool on_output_row() const { return layout_.output_stride == 1 || n_ % layout_.output_stride == 0; }
    void report_observation();
    void report_step();
    // To the audio streams (y: with two polarisations).
    void deliver_frame(std::span<const double> u, std::span<const double> v, std::span<const double> y = {});
    void report_flight(long flown);
    void report_flight_rows(long flown);
    void report_snapshots();
    void report_output();
    void report_played();
    double audit_energy();  // H at this step, into the summary; throws SolverError if not finite
    // Throws SolverError, naming the first non-finite quantity, unless h and the dissipated
    // energy are finite. The test inline (every step at audio rates), the message apart.
    void check_state(double h) const {
        if (!std::isfinite(h) || !std::isfinite(stepper_.dissipated())) report_bad_state(h);
    }
    [[noreturn, gnu::cold]] void report_bad_state(double h) const;
    void report_progress();
    void finish_summary();

    const Case& case_;
    std::span<RunObserver* const> observers_;
    const RunOptions& options_;
    Clock::time_point start_, last_progress_;
    ScreeningChoice screening_;
    Plan plan_;
    RunLayout layout_;
    Stepper stepper_;
    long n_ = 0;

    std::vector<std::vector<double>> shapes_;  // mode shapes at the observation points
    std::vector<double> bridge_;               // bridge force per unit q_j (see BridgeForce)
    std::vector<const double*> row_rows_;      // the shapes, then the bridge: one output row's products
    std::vector<double> row_values_;
    std::vector<std::vector<double>> shapes_y_;  // the same for y (two polarisations)
    std::vector<double> y_;                    // y at the observation points
    std::vector<std::pair<std::size_t, double>> mirrored_forces_;
    std::vector<double> played_heights_;
    bool audio_wanted_ = false;     // some observer asked for audio: the run takes a frame every step
    bool velocity_wanted_ = false;  // the velocity too
    std::optional<SnapshotTaps> snapshots_;  // made with the observers (connect_observers)
    std::vector<double> u_, step_u_, step_v_, flight_u_, flight_v_;
    long step_u_at_ = -1;  // the step whose probe products step_u_ holds (an output row reuses them)

    std::optional<FreeFlight> flight_;
    std::size_t head_ = 0;  // modes stepped one by one during free flight
    std::size_t check_head_ = 0;  // the same while the audio band is written in closed form
    std::optional<AudioStreams> audio_;  // the resamplers, and the samples on their way to the observers
    std::optional<AudioBand> band_;
    // After audio_ and band_ (destroyed before them: its thread runs their jobs).
    std::optional<PerStepQueue> per_step_queue_;

    EnergyAudit audit_;
    long audited_step_ = -1;
    RunSummary summary_;
};

}  // namespace fretbuzz
