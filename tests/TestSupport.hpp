#pragma once
// Helpers shared by the tests: running the fretbuzz program, scratch directories,
// and small synthetic cases built in code.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <sndfile.h>
#include <string>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/scheme/SamplingCheck.hpp"

namespace fretbuzz::testing {

// Every frame of an audio file libsndfile reads (WAV, Ogg, ...), first channel of a mono file;
// empty if it cannot be opened.
inline std::vector<double> read_audio(const std::filesystem::path& path) {
    SF_INFO info{};
    SNDFILE* f = sf_open(path.c_str(), SFM_READ, &info);
    if (f == nullptr) return {};
    std::vector<double> x(static_cast<std::size_t>(info.frames));
    sf_read_double(f, x.data(), info.frames);
    sf_close(f);
    return x;
}

// ||a - b|| / ||b|| over the samples both have.
inline double relative_l2(const std::vector<double>& a, const std::vector<double>& b) {
    double diff = 0.0, norm = 0.0;
    for (std::size_t k = 0; k < std::min(a.size(), b.size()); ++k) {
        diff += (a[k] - b[k]) * (a[k] - b[k]);
        norm += b[k] * b[k];
    }
    return std::sqrt(diff / norm);
}

// A built-in case at the sampling rate fs with only its modes below fs/2 (as `fretbuzz run
// NAME --fs FS` keeps them), for the given duration.
inline Case builtin_at_rate(const std::string& name, double fs, double duration_s) {
    Case c = with_mode_count(read_case_text(name), modes_below_nyquist(load_case(name).modes, fs));
    c.run.sample_rate_hz = fs;
    c.run.duration_s = duration_s;
    return c;
}

struct CommandResult {
    int exit_code = 0;
    std::string output;  // stdout and stderr together
};

// Runs a shell command line, its stderr with its stdout.
inline CommandResult run_shell(const std::string& command) {
    CommandResult result;
    FILE* pipe = ::popen(("(" + command + ") 2>&1").c_str(), "r");
    if (pipe == nullptr) return {-1, "popen failed"};
    char buffer[4096];
    while (const std::size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) result.output.append(buffer, n);
    const int status = ::pclose(pipe);
    result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return result;
}

// Runs the fretbuzz CLI with the given arguments (a shell-quoted string).
inline CommandResult run_cli(const std::string& arguments) { return run_shell(std::string(FRETBUZZ_CLI) + " " + arguments); }

// A fresh, empty directory removed when the object goes away.
class ScratchDir {
public:
    explicit ScratchDir(const std::string& tag) {
        std::random_device rd;
        path_ = std::filesystem::temp_directory_path() / ("fretbuzz-test-" + tag + "-" + std::to_string(rd()));
        std::filesystem::create_directories(path_);
    }
    ~ScratchDir() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    const std::filesystem::path& path() const { return path_; }
    std::string str() const { return path_.string(); }

private:
    std::filesystem::path path_;
};

}  // namespace fretbuzz::testing
