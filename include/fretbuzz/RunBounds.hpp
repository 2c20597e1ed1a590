#pragma once
// The bounds every run keeps, whichever case (one string, strings on a bridge) and whichever
// stack runs it, checked after every override (--duration, --fs, --audio-rate, Python's
// keywords) and before anything is created on disk.
#include <string>

#include "fretbuzz/Case.hpp"

namespace fretbuzz {

// fs > 0, 1 to 4e9 steps (fs * duration, rounded as the run counts them), an output rate in
// (0, fs], an audio rate in [8000, 384000] Hz. Throws InputError naming the key; `audio_key`
// is how the case names its audio rate ("audio.rate", a strings case's "run.audio_rate").
void check_run_bounds(const RunSettings& run, const std::string& audio_key = "audio.rate");

}  // namespace fretbuzz
