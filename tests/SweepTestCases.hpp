#pragma once
// A small ideal string (harmonic modes, no losses) over one point obstacle, written as a
// case file, and sweep specs over it: cheap enough to run many times in the tests.
#include <filesystem>
#include <fstream>
#include <string>

namespace fretbuzz::testing {

// Plucked 1 mm at x = 0.5 m (triangle), a point obstacle 0.05 mm below the string at
// x = 0.6 m, observed at x = 0.55 m; 199 modes, fs = 400 kHz, 10 ms.
inline std::string note_case_text() {
    return R"(name = "sweep-note"
[string]
L = 0.65
T = 70.0
mu = 5e-4
modes = 199
[modes.frequency]
model = "harmonic"
[modes.damping]
model = "none"
[obstacle]
type = "points"
x = [0.6]
height = -0.05e-3
[excitation]
type = "triangle"
position = 0.5
amplitude = 1e-3
[contact]
K = 1e10
alpha = 1.5
[run]
fs = 400000
duration = 0.01
output_rate = 40000
[observe]
x = [0.55]
)";
}

inline void write_text(const std::filesystem::path& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    out << text;
}

inline std::string read_text(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

}  // namespace fretbuzz::testing
