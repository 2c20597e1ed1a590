// libFuzzer target: any bytes as a recording for `fretbuzz estimate` (WAV, FLAC, AIFF through
// libsndfile). Decoding may refuse the input (InputError), never crash, hang, read out of
// bounds or allocate what the bytes claim rather than what they hold.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/analysis/Recording.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view bytes(reinterpret_cast<const char*>(data), size);
    try {
        const fretbuzz::Recording r = fretbuzz::decode_recording(bytes, "fuzz.wav", 1);
        // Every frame kept is one the bytes held (a header's frame count is never trusted).
        if (r.samples.size() > static_cast<std::size_t>(fretbuzz::RecordingLimits{}.max_seconds * r.rate_hz) + 1)
            __builtin_trap();
    } catch (const fretbuzz::InputError&) {
    }
    return 0;
}
