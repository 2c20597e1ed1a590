#pragma once
// Where a run's outputs come from: the fretbuzz version, when, how it was asked for and on
// what platform, and the case it ran (its text's SHA-256 and the mode table it resolved
// to). summary.json and results.h5 both carry it, so a result file explains itself.
#include <string>
#include <string_view>

#include "fretbuzz/Case.hpp"

namespace fretbuzz {

struct Provenance {
    std::string version;       // fretbuzz version
    std::string created_utc;   // ISO 8601, e.g. 2026-11-22T21:05:00Z
    std::string command_line;  // the command (or Python call) that asked for the run
    std::string platform;      // operating system, machine and compiler
};

// The provenance of a run started now by `command_line`.
Provenance current_provenance(std::string command_line);

// SHA-256 of `bytes` as 64 lower-case hex digits (what `sha256sum` prints for them).
std::string sha256_hex(std::string_view bytes);

// The provenance block of summary.json, as a JSON object's text: the fields above, the
// case's name, text and text hash, and its mode table (mode, frequency_hz, sigma_per_s,
// source).
std::string provenance_json(const Provenance& provenance, const Case& c);

}  // namespace fretbuzz
