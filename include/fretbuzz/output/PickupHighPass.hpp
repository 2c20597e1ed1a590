#pragma once
// What a pickup and its signal chain pass of the string's motion: no DC. The displacement at
// a point holds a static part wherever the string is held out of line (a fretted note: the
// pressed string sits about 0.1 of the audio file's full scale below its line); a magnetic
// pickup senses the motion, not the position, and an audio input is AC-coupled, so neither
// passes it. Modelled as a second-order Butterworth high-pass (the bilinear transform of
// s^2 / (s^2 + sqrt(2) w_c s + w_c^2)) with its corner at 5 Hz, far below the lowest note of
// a string instrument (B0 = 30.9 Hz on a five-string bass: -0.003 dB there; -0.001 dB at E1,
// 41.2 Hz). Applied to audio files only; the data files keep the displacement itself.
// It starts from rest (the signal before the first sample counts as 0): a released string,
// which swings about its line from its first sample on, passes as it is. No allocation: two
// numbers of state, one sample at a time.
namespace fretbuzz {

class PickupHighPass {
public:
    static constexpr double kCornerHz = 5.0;

    explicit PickupHighPass(double rate_hz, double corner_hz = kCornerHz);

    double operator()(double x) {  // transposed direct form II
        const double y = b0_ * x + s1_;
        s1_ = b1_ * x - a1_ * y + s2_;
        s2_ = b2_ * x - a2_ * y;
        return y;
    }

private:
    double b0_, b1_, b2_, a1_, a2_;
    double s1_ = 0.0, s2_ = 0.0;
};

}  // namespace fretbuzz
