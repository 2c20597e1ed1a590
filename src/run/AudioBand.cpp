#include "AudioBand.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "../numerics/Multiversion.hpp"
#include "PerStepQueue.hpp"
#include "fretbuzz/run/Resampler.hpp"
#include "fretbuzz/numerics/Kernels.hpp"

namespace fretbuzz {

namespace {
// Output samples added to the measured reach: the closed form and the segments overlap a little.
constexpr long kReachMargin = 2;
// Output samples per closed-form job on the per-step thread.
constexpr long kBatchSamples = 4096;

long floor_div(long a, long b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

// a_j *= w_j for complex values held as parts (vectorises: no sum). Four modes per
// instruction where the processor has AVX2: the closed form's samples and the restarts'
// frames turn every phasor once per sample.
FRETBUZZ_MULTIVERSION void rotate(double* __restrict ar, double* __restrict ai, const double* __restrict wr, const double* __restrict wi,
            std::size_t n) {
    for (std::size_t j = 0; j < n; ++j) {
        const double re = ar[j] * wr[j] - ai[j] * wi[j];
        ai[j] = ar[j] * wi[j] + ai[j] * wr[j];
        ar[j] = re;
    }
}
}  // namespace

bool AudioBand::applies(const AudioStreams& streams, const ModalPropagator& propagator, std::size_t head,
                        long output_stride) {
    const Resampler* r = streams.common_resampler();
    if (r == nullptr || r->input_period() <= 0 || output_stride <= 1) return false;
    std::complex<double> c, z;
    for (std::size_t j = 0; j < head; ++j)
        if (!propagator.free_phasor(j, 1.0, 0.0, c, z)) return false;
    return true;
}

AudioBand::AudioBand(AudioStreams& streams, const ModalPropagator& propagator, std::size_t head,
                     std::span<const std::vector<double>> shapes, long output_stride, PerStepQueue* queue)
    : streams_(streams),
      queue_(queue),
      propagator_(propagator),
      dt_(propagator.dt()),
      head_(head),
      points_(shapes.size()),
      velocity_(streams.wants_velocity()) {
    const Resampler& r = *streams.common_resampler();
    rate_ = r.output_rate_hz();
    input_period_ = r.input_period();
    output_period_ = r.output_period();
    reach_ = r.reach() + kReachMargin;
    reach_steps_ = static_cast<long>(std::ceil(static_cast<double>(reach_) / rate_ / dt_));
    entry_steps_ = 2 * reach_steps_ + input_period_ + output_stride;
    streams_.hold_back(reach_);
    // Inline (no queue), each flight's samples at once, as before there was a queue.
    batch_steps_ = queue_ != nullptr ? kBatchSamples * input_period_ / std::max(1L, output_period_) : 0;
    z_.resize(head);
    std::complex<double> c;
    for (std::size_t j = 0; j < head; ++j) propagator.free_phasor(j, 1.0, 0.0, c, z_[j]);
    // Modes with a gain: below the output Nyquist frequency (the stopband starts there).
    band_ = 0;
    while (band_ < head && z_[band_].imag() < std::numbers::pi * rate_) ++band_;
    for (Phasors* p : {&step_, &rate_turn_, &difference_}) {
        p->re.resize(head);
        p->im.resize(head);
    }
    for (std::size_t j = 0; j < head; ++j) {
        const std::complex<double> step = std::exp(z_[j] * dt_), turn = std::exp(z_[j] / rate_);
        // 1 - e^{-z dt} = -expm1(-z dt), its real part without cancellation
        const double decay = std::expm1(-z_[j].real() * dt_);  // e^{sigma dt} - 1
        const double wt = z_[j].imag() * dt_;
        const std::complex<double> diff{-(decay - 2.0 * (1.0 + decay) * std::sin(0.5 * wt) * std::sin(0.5 * wt)),
                                        (1.0 + decay) * std::sin(wt)};
        step_.re[j] = step.real();
        step_.im[j] = step.imag();
        rate_turn_.re[j] = turn.real();
        rate_turn_.im[j] = turn.imag();
        difference_.re[j] = diff.real() / dt_;
        difference_.im[j] = diff.imag() / dt_;
    }
    shape_.resize(points_ * head);
    shape_velocity_.re.resize(points_ * head);
    shape_velocity_.im.resize(points_ * head);
    for (Phasors* p : {&gain_u_, &gain_v_}) {
        p->re.resize(points_ * band_);
        p->im.resize(points_ * band_);
    }
    for (std::size_t p = 0; p < points_; ++p) {
        std::copy_n(shapes[p].begin(), head, shape_.begin() + static_cast<std::ptrdiff_t>(p * head));
        for (std::size_t j = 0; j < head; ++j) {
            shape_velocity_.re[p * head + j] = shapes[p][j] * difference_.re[j];
            shape_velocity_.im[p * head + j] = shapes[p][j] * difference_.im[j];
        }
        for (std::size_t j = 0; j < band_; ++j) {
            const std::complex<double> g = shapes[p][j] * r.gain(z_[j]);
            const std::complex<double> gv = g * std::complex<double>(difference_.re[j], difference_.im[j]);
            gain_u_.re[p * band_ + j] = g.real();
            gain_u_.im[p * band_ + j] = g.imag();
            gain_v_.re[p * band_ + j] = gv.real();
            gain_v_.im[p * band_ + j] = gv.imag();
        }
    }
}

void AudioBand::anchor(std::span<const double> q, std::span<const double> d, double t_minus_tn, std::size_t count,
                       Phasors& out) const {
    out.re.resize(count);
    out.im.resize(count);
    std::complex<double> c, z;
    for (std::size_t j = 0; j < count; ++j) {
        propagator_.free_phasor(j, q[j], d[j], c, z);
        const std::complex<double> a = c * std::exp(z * t_minus_tn);
        out.re[j] = a.real();
        out.im[j] = a.imag();
    }
}

std::vector<double> AudioBand::head_of(std::span<const double> x) const {
    return {x.begin(), x.begin() + static_cast<std::ptrdiff_t>(head_)};
}

template <class Job>
void AudioBand::run(Job&& job) {
    if (queue_ != nullptr)
        queue_->post(std::forward<Job>(job));
    else
        job();
}

void AudioBand::flown(long n, bool complete, std::span<const double> q, std::span<const double> d) {
    if (in_band_) {
        if (!complete) return;
        if (due_step_ < 0) due_since_ = n;
        due_step_ = n;
        if (n - due_since_ >= batch_steps_) post_due_samples();
        return;
    }
    if (complete && n - free_since_ >= entry_steps_) {
        in_band_ = true;
        run([this, n, q = head_of(q), d = head_of(d)] { enter(n, q, d); });
    }
}

void AudioBand::post_due_samples() {
    if (due_step_ < 0) return;
    const long n = due_step_;
    due_step_ = -1;
    run([this, n] { emit(n); });
}

void AudioBand::enter(long n, const std::vector<double>& q, const std::vector<double>& d) {
    // The last output at or before t_n, less the reach: the segment's outputs up to there never
    // felt its end; the closed form's from there on never feel the stretch's start.
    const long last = floor_div(n * output_period_, input_period_) - reach_;
    streams_.end_segment(last);
    next_sample_ = last + 1;
    closed_from_ = next_sample_;
    anchor(q, d, static_cast<double>(next_sample_) / rate_ - static_cast<double>(n) * dt_, band_, now_);
    emit(n);
}

void AudioBand::emit(long up_to_step) {
    // Samples at or before t = up_to_step dt: k input_period <= up_to_step output_period.
    const long last = floor_div(up_to_step * output_period_, input_period_);
    if (last < next_sample_) return;
    const auto count = static_cast<std::size_t>(last - next_sample_ + 1);
    u_.assign(count * points_, 0.0);
    v_.assign(velocity_ ? count * points_ : 0, 0.0);
    const std::size_t b = band_;
    double* ar = now_.re.data();
    double* ai = now_.im.data();
    const double* wr = rate_turn_.re.data();
    const double* wi = rate_turn_.im.data();
    for (std::size_t k = 0; k < count; ++k) {
        // Re(g a) summed over the modes, in the kernels' vectorised sums.
        for (std::size_t p = 0; p < points_; ++p) {
            u_[k * points_ + p] = kernels::dot(gain_u_.re.data() + p * b, ar, b) - kernels::dot(gain_u_.im.data() + p * b, ai, b);
            if (velocity_)
                v_[k * points_ + p] =
                    kernels::dot(gain_v_.re.data() + p * b, ar, b) - kernels::dot(gain_v_.im.data() + p * b, ai, b);
        }
        rotate(ar, ai, wr, wi, b);
    }
    streams_.band_samples(next_sample_, u_, v_);
    next_sample_ = last + 1;
    // Contact may come back at this step at the earliest: a segment would start from there.
    streams_.settled_before(restart_sample(up_to_step));
}

void AudioBand::resume(long n, std::span<const double> q, std::span<const double> d) {
    if (!in_band_) return;
    // The motion was free up to n: the closed form's samples up to there are due, so that
    // the segment started again for n (from 2 reach before it, however far n lies past the
    // last complete flight) finds them up to its first sample.
    due_step_ = n;
    post_due_samples();
    in_band_ = false;
    free_since_ = n;
    run([this, n, q = head_of(q), d = head_of(d)] { regenerate(n, q, d); });
}

long AudioBand::segment_start(long n) const {
    return std::max(0L, floor_div(n - 2 * reach_steps_, input_period_) * input_period_);
}

long AudioBand::first_valid(long start) const { return start / input_period_ * output_period_ + reach_; }

long AudioBand::restart_sample(long n) const {
    // Valid from 1 reach after its start, 2 reach before n: about 1 reach before t_n. That is
    // where the segment before the band ended (and handed out its samples, which never felt
    // its end) when the band was entered at n or within the rounding of n to the output
    // grid: then the new segment starts after them, never writing a sample handed out.
    return std::max(first_valid(segment_start(n)), closed_from_);
}

void AudioBand::regenerate(long n, const std::vector<double>& q, const std::vector<double>& d) {
    // A fresh stream from a step on the output grid, 2 reach before n: its outputs are valid
    // from 1 reach after its start, while the closed form's still are.
    const long start = segment_start(n);
    streams_.begin_segment(start, restart_sample(n));
    // The free motion of the modes the flights feed, step by step from `start` to n.
    Phasors b;
    anchor(q, d, static_cast<double>(start - n) * dt_, head_, b);
    const std::size_t h = head_;
    std::vector<double> frame_u(points_), frame_v(velocity_ ? points_ : 0);
    for (long m = start; m <= n; ++m) {
        for (std::size_t p = 0; p < points_; ++p) {
            frame_u[p] = kernels::dot(shape_.data() + p * h, b.re.data(), h);
            if (velocity_)
                frame_v[p] = kernels::dot(shape_velocity_.re.data() + p * h, b.re.data(), h) -
                             kernels::dot(shape_velocity_.im.data() + p * h, b.im.data(), h);
        }
        streams_.frame(frame_u, frame_v);
        rotate(b.re.data(), b.im.data(), step_.re.data(), step_.im.data(), h);
    }
}

void AudioBand::flight_start(std::span<const double> q, std::span<const double> d) {
    // (assign: no allocation where the last call's flight did not start)
    flight_q_.assign(q.begin(), q.begin() + static_cast<std::ptrdiff_t>(head_));
    flight_d_.assign(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(head_));
}

void AudioBand::flight_frames(long steps) {
    if (steps <= 0) return;
    auto job = [this, steps, q = std::move(flight_q_), d = std::move(flight_d_)]() mutable {
        free_frames(std::move(q), std::move(d), steps);
    };
    flight_q_ = {};
    flight_d_ = {};
    if (queue_ != nullptr)
        queue_->defer(std::move(job), static_cast<std::size_t>(steps));
    else
        job();
}

void AudioBand::free_frames(std::vector<double> q, std::vector<double> d, long steps) {
    // The audio modes stepped from the flight's start as the flight steps them, and the pickup
    // read as its probes read it: the frames the run used to form, bit for bit, at a third of
    // a phasor turn's cost.
    const std::size_t h = head_;
    const double* e = propagator_.decay().data();
    const double* beta = propagator_.beta().data();
    std::vector<double> frame_u(points_), frame_v(velocity_ ? points_ : 0);
    for (long m = 0; m < steps; ++m) {
        kernels::advance(e, beta, nullptr, nullptr, q.data(), d.data(), h);
        for (std::size_t p = 0; p < points_; ++p) {
            frame_u[p] = kernels::dot(shape_.data() + p * h, q.data(), h);
            if (velocity_) frame_v[p] = kernels::dot(shape_.data() + p * h, d.data(), h) / dt_;
        }
        streams_.frame(frame_u, frame_v);
    }
}

}  // namespace fretbuzz
