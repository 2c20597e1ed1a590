#pragma once
// The resampled (audio) signal of a run without stepping the audio band at the simulation
// rate where that is exact. While no contact can act, every mode moves freely: q_j(t) =
// Re(c_j e^{z_j t}), and the resampler turns e^{z t} into gain(z) e^{z t} at its output
// instants (away from a stream's ends). So over long free stretches the output samples are
// written in closed form, sample by sample at the output rate, and the resampler gets the
// per-step signal only in segments around contacts. A segment ends `reach` output samples
// before the end of its input (later outputs would feel the cut); the closed form starts
// there, `reach` samples after the free stretch began. A segment that starts again (contact
// may come) begins 2 reach before that step with the free motion regenerated step by step,
// so its outputs are valid before the closed-form ones stop being: the closed form is written
// up to that step, and the segment takes over 1 reach before it, or where the closed form
// began if that is later (the band was entered at that step: the samples before were handed
// out then). At every ratio of the rates (1 included) no sample is written after it was
// handed out. At the run's end the last segment is flushed as the resampler always was.
#include <complex>
#include <cstddef>
#include <span>
#include <vector>

#include "AudioStreams.hpp"
#include "fretbuzz/scheme/ModalPropagator.hpp"

namespace fretbuzz {

class PerStepQueue;

class AudioBand {
public:
    // Whether the audio streams all resample to one rate along z (one filter describes them),
    // and the modes fed to them during flights (the first `head`) all have a closed form.
    static bool applies(const AudioStreams& streams, const ModalPropagator& propagator, std::size_t head,
                        long output_stride);
    // With a queue, the synthesis (and every call to the streams) runs on the queue's thread,
    // in order; without, here. Which steps are in the band is decided here either way.
    AudioBand(AudioStreams& streams, const ModalPropagator& propagator, std::size_t head,
              std::span<const std::vector<double>> shapes, long output_stride, PerStepQueue* queue = nullptr);

    // True while the observers want no per-step frames.
    bool in_band() const { return in_band_; }
    // After a flight that reached step n with state (q, d); complete: it ran to an output step.
    void flown(long n, bool complete, std::span<const double> q, std::span<const double> d);
    // After a step taken by the scheme (contact may have acted).
    void stepped(long n) { free_since_ = n; }
    // Per-step frames again from step n (state (q, d)) on; the frames up to n are regenerated.
    void resume(long n, std::span<const double> q, std::span<const double> d);
    // A flight out of the band starts at state (q, d): its per-step frames are the audio modes'
    // free motion from there, stepped as the flight steps them (flight_frames, after it has
    // flown `steps`), made where the synthesis runs, in their place among the stepped frames,
    // instead of by the run at every step: the same frames, bit for bit.
    void flight_start(std::span<const double> q, std::span<const double> d);
    void flight_frames(long steps);

private:
    struct Phasors {  // one complex value per mode, split into parts (vectorises)
        std::vector<double> re, im;
    };
    // The synthesis: entering the band at step n, its samples up to a step, and the per-step
    // frames regenerated up to step n on leaving it. q and d hold the first head_ modes.
    void enter(long n, const std::vector<double>& q, const std::vector<double>& d);
    void emit(long up_to_step);
    void regenerate(long n, const std::vector<double>& q, const std::vector<double>& d);
    void free_frames(std::vector<double> q, std::vector<double> d, long steps);  // (stepped: copies)
    template <class Job>
    void run(Job&& job);
    void post_due_samples();  // the samples flights have made due, as one job
    long segment_start(long n) const;  // where a segment that starts again at step n begins
    long first_valid(long start) const;  // its first output sample that never felt its start
    long restart_sample(long n) const;   // the first sample such a segment writes
    std::vector<double> head_of(std::span<const double> x) const;  // the first head_ values: what a job keeps of q or d
    // c_j e^{z_j (t - t_n)} for the first `count` modes, from the state at step n.
    void anchor(std::span<const double> q, std::span<const double> d, double t_minus_tn, std::size_t count,
                Phasors& out) const;

    AudioStreams& streams_;
    PerStepQueue* queue_;
    const ModalPropagator& propagator_;
    double dt_, rate_;
    long input_period_, output_period_;  // steps and output samples spanning the same time
    long reach_;                          // output samples, with a margin
    long reach_steps_;
    long entry_steps_;                    // free steps before the closed form takes over
    std::size_t head_, band_;             // modes regenerated (the flights' head) / with a gain
    std::size_t points_;
    bool velocity_;
    std::vector<std::complex<double>> z_;
    std::vector<double> shape_;           // points x head: mode shapes at the points
    Phasors shape_velocity_;              // the same x difference
    Phasors step_, rate_turn_;            // e^{z dt}, e^{z / rate}
    Phasors difference_;                  // (1 - e^{-z dt}) / dt: velocity of the per-step signal
    Phasors gain_u_, gain_v_;             // points x band: shape x gain (x difference)
    Phasors now_;                         // the closed form at sample next_sample_
    bool in_band_ = false;  // (the decisions: read and written by the run's thread only)
    long free_since_ = 0;
    long next_sample_ = 0;  // (the synthesis' state: touched by its jobs only)
    long closed_from_ = 0;  // the closed form's first sample since the band was entered
    // With a queue, a flight's samples (one output interval) are gathered into one job per
    // batch_steps_ (0 inline: each flight's at once): a job per interval would cost more in
    // waking the thread than it saves.
    long due_step_ = -1, due_since_ = 0, batch_steps_ = 0;
    std::vector<double> flight_q_, flight_d_;  // the first head_ modes where a flight starts
    std::vector<double> u_, v_;
};

}  // namespace fretbuzz
