#include "fretbuzz/scheme/PenaltyContact.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "../numerics/Multiversion.hpp"
#include "fretbuzz/Error.hpp"

namespace fretbuzz {

namespace {
constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr int kMaxIterations = 200;

#if defined(__GNUC__)
// 32-byte vectors pass differently with and without AVX: the helpers taking them are inlined.
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
#if defined(__GNUC__)
#define FRETBUZZ_INLINE [[gnu::always_inline]] inline
#else
#define FRETBUZZ_INLINE inline
#endif
// The batch is compiled for each processor variant (FRETBUZZ_MULTIVERSION): each lane does the
// scalar solve's operations in its order (where a variant fuses multiply-adds, the results
// agree with the scalar solve's to round-off).
typedef double v4 __attribute__((vector_size(32)));
using m4 = decltype(v4{} < v4{});  // lane masks: -1 true, 0 false

// sqrt where x > 0 (0 elsewhere: such lanes are not used), correctly rounded as std::sqrt. The
// file is built without errno (-fno-math-errno): the four roots become one vector instruction
// where the variant has one (AVX), two where it has 2-lane ones.
FRETBUZZ_INLINE v4 sqrt4(const v4& x) {
    const v4 positive = x > 0.0 ? x : v4{};
    v4 root;
    for (int l = 0; l < 4; ++l) root[l] = __builtin_sqrt(positive[l]);
    return root;
}
FRETBUZZ_INLINE v4 abs4(const v4& x) { return (v4)((m4)x & 0x7fffffffffffffffL); }

// Whether any lane is set. On x86-64, from the lanes' sign bits (two instructions, 2-lane ones
// that every variant has): moving the four lanes out one by one cost more than the test itself.
FRETBUZZ_INLINE bool any4(const m4& m) {
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
    typedef double v2 __attribute__((vector_size(16)));
    const v4 bits = (v4)m;
    const v2 low = __builtin_shufflevector(bits, bits, 0, 1), high = __builtin_shufflevector(bits, bits, 2, 3);
    return (__builtin_ia32_movmskpd(low) | __builtin_ia32_movmskpd(high)) != 0;
#else
    return (m[0] | m[1] | m[2] | m[3]) != 0;
#endif
}

// quotient(a, r) for alpha = 3/2 (its three cases), and sqrt(a + r) where it is computed
// (kNoRoot elsewhere), as PenaltyContact::quotient with anchor = sqrt(a) or 0, s = sqrt4(a + r).
struct Quotient4 {
    v4 value, root;
};
FRETBUZZ_INLINE Quotient4 quotient_three_halves(const v4& a, const v4& r, const v4& anchor, const v4& s, double stiffness,
                                                double potential_scale) {
    const v4 zero{};
    const m4 a_pos = a > 0.0, ar_pos = (a + r) > 0.0, is_inside = a_pos & ar_pos;
    const v4 sqrt_a = anchor, t = anchor;                         // sqrt(a) where a > 0
    const v4 at_zero = a_pos ? stiffness * (a * sqrt_a) : zero;  // force(a)
    const v4 t2 = t * t;
    const v4 numerator = t2 * t2 + s * (t2 * t + s * (t2 + s * (t + s)));
    const v4 inside = 0.4 * stiffness * numerator / (s + t);
    const m4 at_r_zero = r == 0.0;
    v4 outside = zero;
    if (any4(~is_inside & ~at_r_zero)) {  // a lane landing or leaving (most often none)
        const v4 potential_ar = ar_pos ? potential_scale * (((a + r) * s) * (a + r)) : zero;
        const v4 potential_a = a_pos ? potential_scale * ((a * sqrt_a) * a) : zero;
        outside = (potential_ar - potential_a) / r;
    }
    return {at_r_zero ? at_zero : is_inside ? inside : outside, (is_inside & ~at_r_zero) ? s : zero + kNoRoot};
}

// PenaltyContact::first_iterate_or_b for alpha = 3/2, four equations at once, each lane rounding
// as the scalar code does (the same operations in the same order, no fused multiply-add).
// t = sqrt(a) where a > 0. A landing with a firm touch needs pow (its frozen power): such lanes
// are flagged in `scalar` and left to the scalar code.
FRETBUZZ_INLINE v4 start_three_halves(const v4& a, const v4& b, const v4& t, double k, double stiffness,
                                      double potential_scale, m4& scalar) {
    const v4 zero{};
    const m4 a_pos = a > 0.0;
    const m4 apart = (a <= 0.0) & ((a + b) <= 0.0);
    // a > 0: Psi', Psi'' and Psi at a.
    const v4 d1 = stiffness * (a * t), d2 = (1.5 * stiffness) * t, psi = potential_scale * ((a * t) * a);
    const v4 p = k * psi;
    // Leaving contact: the negative root of r^2 - b r - k Psi(a) in closed form.
    const m4 leaving = a_pos & ((p / a - a - b) >= 0.0);
    v4 leave = zero;
    if (any4(leaving)) {
        const v4 root_disc = sqrt4(b * b + 4.0 * p);
        leave = b > 0.0 ? (-2.0 * p) / (b + root_disc) : 0.5 * (b - root_disc);
    }
    // Staying, unless soft: the root of the Taylor parabola at r = 0, or of its tangent.
    const m4 parabola = a_pos & ~leaving & ~((k * d2) < 0.01);
    v4 stay = b;
    if (any4(parabola)) {
        const v4 d3 = (0.75 * stiffness) / t;
        const v4 c0 = k * d1 - b, c1 = 1.0 + k * (0.5 * d2), c2 = k * (d3 / 6.0);
        const v4 disc = c1 * c1 - (4.0 * c2) * c0;
        const v4 r0 = disc >= 0.0 ? (-2.0 * c0) / (c1 + sqrt4(disc)) : (-c0) / c1;
        const v4 clamped = r0 < -a ? -a : r0;
        stay = parabola ? (r0 > 4.0 * a ? b : clamped) : b;
    }
    // Landing: b where the touch is light (k Psi(a + b) <= 0.01 b^2), else the scalar model.
    const m4 landing = ~a_pos & ~apart;
    scalar = m4{};
    if (any4(landing)) {
        const v4 d = a + b;
        const v4 potential_d = potential_scale * ((d * sqrt4(d)) * d);
        scalar = landing & ~((k * potential_d) <= 0.01 * (b * b));
    }
    const v4 start = leaving ? leave : stay;  // b on landings (the flagged ones are replaced)
    const m4 usable = ~apart & (start - start == 0.0) & (start < b);
    return usable ? start : b;
}

// solve's first iterates for alpha = 3/2, for count (a multiple of 4) equations, and sqrt(a) (0
// where a <= 0, as anchor(a)) for the steps that follow; says whether any lane is flagged in
// need_scalar (its start left to the scalar code).
FRETBUZZ_INLINE bool starts_three_halves(const double* a_in, const double* b_in, std::size_t count, double k,
                                         double stiffness, double potential_scale, double* anchor_out,
                                         double* start_out, long* need_scalar) {
    m4 flagged{};
    for (std::size_t i = 0; i < count; i += 4) {
        v4 a, b;
        __builtin_memcpy(&a, a_in + i, sizeof a);
        __builtin_memcpy(&b, b_in + i, sizeof b);
        m4 scalar;
        const v4 anchor = sqrt4(a);
        const v4 start = start_three_halves(a, b, anchor, k, stiffness, potential_scale, scalar);
        __builtin_memcpy(anchor_out + i, &anchor, sizeof anchor);
        __builtin_memcpy(start_out + i, &start, sizeof start);
        __builtin_memcpy(need_scalar + i, &scalar, sizeof scalar);
        flagged |= scalar;
    }
    return any4(flagged);
}

// The start of PenaltyContact::solve for alpha = 3/2, four equations at a time, each lane
// rounding as the scalar code does: from the first iterates start_in (as solve chose them), the
// stopping tests there and after Newton's first step. Two passes over the block, each with a
// short chain of divisions and square roots per lane group: the groups of one pass are
// independent, so the processor overlaps them.
// state[l] = 0: out of contact (increment b, no force); 1: solved (increment, force, root);
// 2: more iterations needed (left to the scalar solve).
FRETBUZZ_INLINE void first_steps_three_halves(const double* a_in, const double* b_in, const double* anchor_in,
                                              const double* start_in, std::size_t count, double k, double stiffness,
                                              double potential_scale, double* increment, double* force, double* root,
                                              long* state) {
    constexpr int kStepped = 3;  // Newton's step taken, its stopping test still to do
    bool stepped_any = false;
    for (std::size_t i = 0; i < count; i += 4) {
        v4 a, b, r, anchor;
        __builtin_memcpy(&a, a_in + i, sizeof a);
        __builtin_memcpy(&b, b_in + i, sizeof b);
        __builtin_memcpy(&r, start_in + i, sizeof r);
        __builtin_memcpy(&anchor, anchor_in + i, sizeof anchor);
        const v4 zero{};
        const m4 a_pos = a > 0.0;
        const m4 apart = (a <= 0.0) & ((a + b) <= 0.0);
        const v4 root_r = sqrt4(a + r);
        const Quotient4 first = quotient_three_halves(a, r, anchor, root_r, stiffness, potential_scale);
        const v4 f = first.value;
        const v4 other = b - k * f;
        const v4 residual = r == b ? k * f : r + k * f - b;
        const m4 above = residual >= 0.0;
        const v4 hi = above ? r : other;
        v4 lo = above ? other : r;
        lo = ((a <= 0.0) & (lo < -a)) ? -a : lo;
        const v4 scale = abs4(r) + abs4(b) + k * f;
        const v4 wide = abs4(lo) < abs4(hi) ? abs4(hi) : abs4(lo);
        const m4 converged = (abs4(residual) <= 4.0 * kEps * scale) | (hi - lo <= 2.0 * kEps * wide);
        v4 next = r;
        const m4 stepping = ~(converged | apart);
        if (any4(stepping)) {
            stepped_any = true;
            // One Newton step from r: the slope of the quotient (PenaltyContact::slope).
            const m4 ar_pos = (a + r) > 0.0;
            const v4 s = root_r, t = anchor;  // sqrt(a + r), whether the quotient computed it or not
            const v4 sum = s + t;
            const v4 slope_inside =
                0.2 * stiffness * (s * (s * (3.0 * s + 6.0 * t) + 4.0 * t * t) + 2.0 * t * t * t) / (sum * sum);
            v4 slope_outside = zero;
            if (any4(~(a_pos & ar_pos))) {
                const v4 force_ar = ar_pos ? stiffness * ((a + r) * root_r) : zero;
                slope_outside = r == 0.0 ? zero : (force_ar - f) / r;
            }
            const v4 slope = 1.0 + k * ((a_pos & ar_pos) ? slope_inside : slope_outside);
            next = r - residual / slope;
            const m4 usable = (next > lo) & (next < hi) & (next - next == 0.0);
            next = usable ? next : 0.5 * (lo + hi);
        }
        // A non-finite input is left to the scalar solve, which reports it. Written as vectors:
        // lane by lane, moving each value out of its register cost more than the arithmetic.
        const m4 finite = (a - a == 0.0) & (b - b == 0.0);
        const m4 none{}, one = none + 1, two = none + 2, stepped = none + kStepped;
        const m4 code = finite ? (apart ? none : converged ? one : stepped) : two;
        const v4 chosen = converged ? r : next;
        __builtin_memcpy(state + i, &code, sizeof code);
        __builtin_memcpy(increment + i, &chosen, sizeof chosen);
        __builtin_memcpy(force + i, &f, sizeof f);
        __builtin_memcpy(root + i, &first.root, sizeof first.root);
    }
    if (!stepped_any) return;
    // The quotient at Newton's iterate and the stopping test there.
    for (std::size_t i = 0; i < count; i += 4) {
        m4 code;
        __builtin_memcpy(&code, state + i, sizeof code);
        const m4 stepped = code == kStepped;
        if (!any4(stepped)) continue;
        v4 a, b, r, next, anchor;
        __builtin_memcpy(&a, a_in + i, sizeof a);
        __builtin_memcpy(&b, b_in + i, sizeof b);
        __builtin_memcpy(&r, start_in + i, sizeof r);
        __builtin_memcpy(&next, increment + i, sizeof next);
        __builtin_memcpy(&anchor, anchor_in + i, sizeof anchor);
        const Quotient4 second = quotient_three_halves(a, next, anchor, sqrt4(a + next), stiffness, potential_scale);
        const v4 residual_next = next + k * second.value - b;
        const m4 stalled = (abs4(next - r) <= kEps * abs4(next)) | (residual_next == 0.0);
        const m4 none{};
        code = stepped ? (stalled ? none + 1 : none + 2) : code;
        v4 f, rt;
        __builtin_memcpy(&f, force + i, sizeof f);
        __builtin_memcpy(&rt, root + i, sizeof rt);
        f = stepped ? second.value : f;
        rt = stepped ? second.root : rt;
        __builtin_memcpy(state + i, &code, sizeof code);
        __builtin_memcpy(force + i, &f, sizeof f);
        __builtin_memcpy(root + i, &rt, sizeof rt);
    }
}
// The batch's two passes, each compiled for every processor variant.
FRETBUZZ_MULTIVERSION bool starts(const double* a, const double* b, std::size_t count, double k, double stiffness,
                                  double potential_scale, double* anchor, double* start, long* need_scalar) {
    return starts_three_halves(a, b, count, k, stiffness, potential_scale, anchor, start, need_scalar);
}
FRETBUZZ_MULTIVERSION void first_steps(const double* a, const double* b, const double* anchor, const double* start,
                                       std::size_t count, double k, double stiffness, double potential_scale,
                                       double* increment, double* force, double* root, long* state) {
    first_steps_three_halves(a, b, anchor, start, count, k, stiffness, potential_scale, increment, force, root, state);
}
}  // namespace

PenaltyContact::PenaltyContact(double stiffness, double exponent, bool specialise)
    : k_(stiffness), alpha_(exponent), specialise_(specialise) {
    set(stiffness, exponent);
}

void PenaltyContact::set(double stiffness, double exponent) {
    // The checks build their messages only when they fail: a real-time change stays allocation-free.
    if (!(std::isfinite(stiffness) && stiffness > 0.0)) require_positive("contact.K (penalty stiffness)", stiffness);
    if (!(std::isfinite(exponent) && exponent >= 1.0)) require_at_least("contact.alpha (penalty exponent)", exponent, 1.0);
    k_ = stiffness;
    alpha_ = exponent;
    potential_scale_ = k_ / (alpha_ + 1.0);
    law_ = Law::general;
    if (!specialise_) return;
    if (exponent == 1.0) law_ = Law::linear;
    if (exponent == 1.5) law_ = Law::three_halves;
    if (exponent == 2.0) law_ = Law::quadratic;
    if (exponent == 3.0) law_ = Law::cubic;
}

double PenaltyContact::power(double eta) const {
    switch (law_) {
        case Law::linear: return eta;
        case Law::three_halves: return eta * std::sqrt(eta);
        case Law::quadratic: return eta * eta;
        case Law::cubic: return eta * eta * eta;
        case Law::general: break;
    }
    return std::pow(eta, alpha_);
}

double PenaltyContact::potential_of(double eta) const {
    // eta > 0 with no power of it known (potential handles the other cases inline).
    if (law_ == Law::general) return potential_scale_ * std::pow(eta, alpha_ + 1.0);
    return potential_scale_ * (power(eta) * eta);
}

double PenaltyContact::force(double eta) const { return eta > 0.0 ? k_ * power(eta) : 0.0; }

double PenaltyContact::anchor(double a) const {
    // What every quotient of one solve shares: sqrt(a) or a^(alpha+1), computed once.
    if (!(a > 0.0)) return 0.0;
    if (law_ == Law::three_halves) return std::sqrt(a);
    return law_ == Law::general ? std::pow(a, alpha_ + 1.0) : 0.0;
}

double PenaltyContact::quotient_inside(double a, double r, double anchor_a, double& root) const {
    // ((a + r)^(alpha+1) - a^(alpha+1)) / r factored so that every term is positive.
    switch (law_) {
        case Law::linear: return k_ * (a + 0.5 * r);
        case Law::quadratic: return k_ * (a * (a + r) + r * r / 3.0);
        case Law::cubic: {
            const double e = a + r;
            return 0.25 * k_ * (a + e) * (a * a + e * e);
        }
        case Law::three_halves: {  // s^5 - t^5 over s^2 - t^2, s = sqrt(a + r), t = sqrt(a)
            const double s = std::sqrt(a + r), t = anchor_a;
            root = s;  // the slope at r and the potential of a + r use it again
            const double t2 = t * t;
            const double numerator = t2 * t2 + s * (t2 * t + s * (t2 + s * (t + s)));
            return 0.4 * k_ * numerator / (s + t);
        }
        case Law::general: break;
    }
    // K/(alpha+1) a^(alpha+1) [(1 + r/a)^(alpha+1) - 1] / r, accurate for tiny r/a.
    const double growth = std::expm1((alpha_ + 1.0) * std::log1p(r / a));
    root = anchor_a * (1.0 + growth);  // (a + r)^(alpha+1): the slope and the potential at a + r reuse it
    return potential_scale_ * anchor_a * growth / r;
}

double PenaltyContact::quotient(double a, double r, double anchor_a, double& root) const {
    root = kNoRoot;
    if (r == 0.0) return force(a);
    if (a > 0.0 && a + r > 0.0) return quotient_inside(a, r, anchor_a, root);
    // At most one of the two potentials is non-zero here: no cancellation.
    if (law_ == Law::general) {
        // Landing: the power of a + r is kept (the potential of a + r reuses it); leaving: the
        // anchor is Psi(a)'s power. The same values as potential's. (The slope's Psi'(a + r) from
        // that power, root / (a + r), would save one more pow, but moves Newton's path: the
        // contact energy, set by the solve's tolerance, moved by 1e-12 of itself on the sitar.)
        if (a + r > 0.0) {
            root = std::pow(a + r, alpha_ + 1.0);
            return potential_scale_ * root / r;
        }
        return (0.0 - potential_scale_ * anchor_a) / r;
    }
    return (potential(a + r) - potential(a)) / r;
}

double PenaltyContact::difference_quotient(double a, double r) const {
    double root = kNoRoot;
    return quotient(a, r, anchor(a), root);
}

double PenaltyContact::slope_of_quotient(double a, double r, double quotient_value) const {
    return slope(a, r, quotient_value, anchor(a), kNoRoot);
}

PenaltyContact::QuotientSlope PenaltyContact::quotient_and_slope(const Anchored& a, double r) const {
    double root = kNoRoot;
    const double q = quotient(a.a, r, a.power, root);
    // At 3/2 the root is sqrt(a + r), as slope would take it; the general law's slope from its
    // root is another formula, so it goes the way slope_of_quotient does.
    return {q, slope(a.a, r, q, a.power, law_ == Law::general ? kNoRoot : root)};
}

double PenaltyContact::slope(double a, double r, double quotient_value, double anchor_a, double root) const {
    // d/dr of the difference quotient. The closed forms differentiate exactly; otherwise
    // (Psi'(a+r) - quotient) / r, with its limit Psi''(a + r/2) / 2 when r is too small
    // against a for the difference to be accurate.
    if (a > 0.0 && a + r > 0.0) {
        switch (law_) {
            case Law::linear: return 0.5 * k_;
            case Law::quadratic: return k_ * (a + r * (2.0 / 3.0));
            case Law::cubic: {
                const double e = a + r;
                return 0.25 * k_ * (a * a + 2.0 * a * e + 3.0 * e * e);
            }
            case Law::three_halves: {  // sqrt(a + r) as the quotient at r found it, if it did
                const double s = root == kNoRoot ? std::sqrt(a + r) : root, t = anchor_a;
                const double sum = s + t;
                return 0.2 * k_ * (s * (s * (3.0 * s + 6.0 * t) + 4.0 * t * t) + 2.0 * t * t * t) / (sum * sum);
            }
            case Law::general:
                if (root == kNoRoot) break;
                // From the anchor a^(alpha+1) and the power (a + r)^(alpha+1) the quotient left:
                // no pow. Psi''(a)/2 + Psi'''(a) r/3 where r is tiny against a.
                if (std::abs(r) < 1e-4 * a) return k_ * alpha_ * anchor_a / (a * a) * (0.5 + (alpha_ - 1.0) * r / (3.0 * a));
                return (k_ * root / (a + r) - quotient_value) / r;
        }
    }
    if (a > 0.0 && std::abs(r) < 1e-4 * a) return 0.5 * k_ * alpha_ * std::pow(a + 0.5 * r, alpha_ - 1.0);
    if (r == 0.0) return 0.0;
    return (force(a + r) - quotient_value) / r;
}

std::size_t PenaltyContact::solve_all(std::span<const double> a, std::span<const double> b, double k,
                                      std::span<ContactSolution> out) const {
    const std::size_t n = a.size();
    std::size_t i = 0, in_lanes = 0;
    if (law_ == Law::three_halves && std::isfinite(k)) {
        // Blocks of equations on the stack: the first iterates of all, then Newton's first step
        // for all, four lanes at a time with no call per lane.
        constexpr std::size_t kBlock = 64;
        double anchor[kBlock], start[kBlock], increment[kBlock], force[kBlock], root[kBlock];
        long need_scalar[kBlock];
        long state[kBlock];
        while (i + 4 <= n) {
            const std::size_t count = std::min(kBlock, (n - i) / 4 * 4);
            const double* ai = a.data() + i;
            const double* bi = b.data() + i;
            if (starts(ai, bi, count, k, k_, potential_scale_, anchor, start, need_scalar))
                for (std::size_t l = 0; l < count; ++l)
                    if (need_scalar[l] != 0) start[l] = first_iterate_or_b(ai[l], bi[l], k);
            first_steps(ai, bi, anchor, start, count, k, k_, potential_scale_, increment, force, root, state);
            for (std::size_t l = 0; l < count; ++l) {
                const std::size_t j = i + l;
                if (state[l] == 1)
                    out[j] = ContactSolution{increment[l], force[l], 1, root[l]};
                else if (state[l] == 0)
                    out[j] = ContactSolution{bi[l], 0.0, 0, kNoRoot};
                else
                    out[j] = solve(a[j], b[j], k);
                in_lanes += state[l] < 2 ? 1 : 0;
            }
            i += count;
        }
    }
    for (; i < n; ++i) out[i] = solve(a[i], b[i], k);
    return in_lanes;
}

double PenaltyContact::first_iterate(double a, double b, double k, double anchor_a) const {
    if (a > 0.0) {
        double d1 = 0.0, d2 = 0.0, d3 = 0.0, psi = 0.0;  // Psi', Psi'', Psi''' and Psi at a, without pow
        switch (law_) {
            case Law::linear:
                d1 = k_ * a;
                d2 = k_;
                psi = 0.5 * d1 * a;
                break;
            case Law::three_halves:
                d1 = k_ * (a * anchor_a);
                d2 = 1.5 * k_ * anchor_a;
                d3 = 0.75 * k_ / anchor_a;
                psi = potential_scale_ * ((a * anchor_a) * a);
                break;
            case Law::quadratic:
                d1 = k_ * (a * a);
                d2 = 2.0 * k_ * a;
                d3 = 2.0 * k_;
                psi = d1 * a / 3.0;
                break;
            case Law::cubic:
                d1 = k_ * (a * a * a);
                d2 = 3.0 * k_ * (a * a);
                d3 = 6.0 * k_ * a;
                psi = 0.25 * d1 * a;
                break;
            case Law::general:
                d1 = k_ * anchor_a / a;
                d2 = alpha_ * d1 / a;
                d3 = (alpha_ - 1.0) * d2 / a;
                psi = potential_scale_ * anchor_a;
                break;
        }
        // Leaving contact: phi(-a) = -a + k Psi(a)/a - b >= 0 puts the root where a + r <= 0,
        // where phi(r) = r - b - k Psi(a)/r: the negative root of r^2 - b r - k Psi(a), in closed form.
        const double p = k * psi;
        if (p / a - a - b >= 0.0) {
            const double root_disc = std::sqrt(b * b + 4.0 * p);
            return b > 0.0 ? -2.0 * p / (b + root_disc) : 0.5 * (b - root_disc);
        }
        // Staying in contact (the root above -a): the root of phi's second-order Taylor polynomial
        // at r = 0, c0 + c1 r + c2 r^2 (Q(0) = Psi'(a), Q'(0) = Psi''(a)/2, Q''(0) = Psi'''(a)/3),
        // or of its tangent where the parabola misses the axis. Exact for alpha = 1 and 2.
        // A soft contact (k Psi''(a) small against 1): phi is nearly r - b, Newton from b converges at once.
        if (k * d2 < 0.01) return b;
        const double c0 = k * d1 - b, c1 = 1.0 + k * (0.5 * d2), c2 = k * (d3 / 6.0);
        const double disc = c1 * c1 - 4.0 * c2 * c0;
        const double r0 = disc >= 0.0 ? -2.0 * c0 / (c1 + std::sqrt(disc)) : -c0 / c1;
        // The parabola models phi only for r of the order of a: beyond, Newton from b.
        if (r0 > 4.0 * a) return b;
        return std::max(r0, -a);
    }
    // Landing (a <= 0 < a + b): y = a + r > 0 solves (y - a)(d - y) = c y^(alpha+1), d = a + b,
    // c = k K/(alpha+1). With y^(alpha+1) taken as y^2 y0^(alpha-1), y0 the larger of the two
    // one-term balances (c y^alpha = d, c y^(alpha+1) = -a d), a quadratic in y: exact for alpha = 1.
    const double c = k * potential_scale_, d = a + b;
    // Where the force at b is small against b (a light touch), Newton from b is as good.
    if (k * potential(d) <= 0.01 * (b * b)) return b;
    double growth = 1.0;  // y0^(alpha-1)
    if (law_ != Law::linear) {
        const double y0 = landing_scale(a, d, c);
        growth = law_ == Law::three_halves ? std::sqrt(y0) : std::pow(y0, alpha_ - 1.0);
    }
    // (1 + c y0^(alpha-1)) y^2 - (a + d) y + a d = 0, its positive root without cancellation.
    const double curvature = 1.0 + c * growth, m = a + d;
    const double root_disc = std::sqrt(m * m - 4.0 * curvature * (a * d));
    const double y = m >= 0.0 ? (m + root_disc) / (2.0 * curvature) : -2.0 * (a * d) / (root_disc - m);
    return y - a;
}

double PenaltyContact::landing_scale(double a, double d, double c) const {
    // max(y1, y2), y1 = (d/c)^(1/alpha), y2 = (-a d/c)^(1/(alpha+1)): y1 >= y2 exactly where
    // y1 >= -a (raise both to the power alpha + 1), so one pow decides unless the two are within
    // round-off of each other (then both, as the max of the two computed values).
    // Near that edge y1/y2 = (y1/-a)^(1/(alpha+1)): a margin of 1e-9 (alpha + 1) keeps the two
    // computed pows (1 ulp each) on the same sides.
    const double y1 = std::pow(d / c, 1.0 / alpha_), margin = 1e-9 * (alpha_ + 1.0);
    if (y1 > -a * (1.0 + margin)) return y1;
    const double y2 = std::pow(-a * d / c, 1.0 / (alpha_ + 1.0));
    return y1 < -a * (1.0 - margin) ? y2 : std::max(y1, y2);
}

double PenaltyContact::first_iterate_or_b(double a, double b, double k, double anchor_a) const {
    if (a <= 0.0 && a + b <= 0.0) return b;  // out of contact: no model
    const double start = first_iterate(a, b, k, anchor_a);
    return std::isfinite(start) && start < b ? start : b;  // phi(b) >= 0: never above b
}

double PenaltyContact::first_iterate_or_b(double a, double b, double k) const {
    return std::isfinite(a) && std::isfinite(b) ? first_iterate_or_b(a, b, k, anchor(a)) : b;
}

ContactSolution PenaltyContact::solve_from_b(double a, double b, double k) const { return solve(a, b, k, false); }

ContactSolution PenaltyContact::solve(double a, double b, double k, bool model_start) const {
    ContactSolution s;
    if (!std::isfinite(a) || !std::isfinite(b) || !std::isfinite(k)) {
        std::ostringstream msg;
        msg << "contact solve received a non-finite state (eta^{n-1} = " << a << ", b = " << b << ", dt^2/mu = " << k
            << "): the simulation has diverged";
        throw SolverError(msg.str());
    }
    if (a <= 0.0 && a + b <= 0.0) {  // stays out of contact over both steps: no force
        s.increment = b;
        return s;
    }
    const double anchor_a = anchor(a);
    // phi(r) = r + k Q(r) - b is increasing and convex (Q averages Psi', which is convex).
    // Newton's method from b converges from above, slowly while far (K [eta]^alpha grows fast);
    // the model's first iterate (first_iterate) is most often within round-off after 2 or 3 steps.
    double r = model_start ? first_iterate_or_b(a, b, k, anchor_a) : b;
    double root = kNoRoot, root_next = kNoRoot, root_mid = kNoRoot;  // powers of a + r where known
    double f = quotient(a, r, anchor_a, root);
    // Q is non-decreasing, so phi(b - k Q(r)) = k (Q(b - k Q(r)) - Q(r)) has the sign opposite
    // to phi(r) (or is 0): the root lies between r and b - k Q(r).
    const double other = b - k * f;
    double residual = r == b ? k * f : r + k * f - b;  // phi(r)
    double lo = residual >= 0.0 ? other : r, hi = residual >= 0.0 ? r : other;
    if (a <= 0.0) lo = std::max(lo, -a);  // no force while a + r <= 0, so phi < 0 there
    for (int it = 1; it <= kMaxIterations; ++it) {
        s.iterations = it;
        const double scale = std::abs(r) + std::abs(b) + k * f;
        if (std::abs(residual) <= 4.0 * kEps * scale || hi - lo <= 2.0 * kEps * std::max(std::abs(lo), std::abs(hi))) {
            s.increment = r;
            s.force = f;
            s.root = root;
            return s;
        }
        const double slope = 1.0 + k * this->slope(a, r, f, anchor_a, root);
        double next = r - residual / slope;
        // Keep inside the bracket; bisect when Newton would leave it or stalls.
        if (!(next > lo && next < hi) || !std::isfinite(next)) next = 0.5 * (lo + hi);
        const double f_next = quotient(a, next, anchor_a, root_next);
        const double residual_next = next + k * f_next - b;
        if (residual_next > 0.0)
            hi = next;
        else
            lo = next;
        if (std::abs(next - r) <= kEps * std::abs(next) || residual_next == 0.0) {
            s.increment = next;
            s.force = f_next;
            s.root = root_next;
            s.iterations = it;
            return s;
        }
        // If Newton crawls (a strongly curved law from far away), halve the bracket too.
        if (hi - lo > 0.0 && std::abs(residual_next) > 0.5 * std::abs(residual) && it % 4 == 0) {
            const double mid = 0.5 * (lo + hi);
            const double f_mid = quotient(a, mid, anchor_a, root_mid);
            const double residual_mid = mid + k * f_mid - b;
            (residual_mid > 0.0 ? hi : lo) = mid;
            if (std::abs(residual_mid) < std::abs(residual_next)) {
                r = mid;
                f = f_mid;
                root = root_mid;
                residual = residual_mid;
                continue;
            }
        }
        r = next;
        f = f_next;
        root = root_next;
        residual = residual_next;
    }
    std::ostringstream msg;
    msg.precision(17);
    msg << "contact solve did not converge in " << kMaxIterations << " iterations (K = " << k_
        << ", alpha = " << alpha_ << ", eta^{n-1} = " << a << ", b = " << b << ", dt^2/mu = " << k
        << "); reduce contact.K or the time step";
    throw SolverError(msg.str());
}

}  // namespace fretbuzz
