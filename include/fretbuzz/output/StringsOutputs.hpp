#pragma once
// The files of a run of strings on a bridge (StringsRun), all or nothing: strings.csv (t, each
// string's energy by its name, the bridge's, the balance), bridge.wav (the bridge's speed) and
// one pickup_<name>.wav per string, the case file as read, and summary.json (what report.html
// tabulates: the case, rates, steps, the strings' names, the worst balance).
#include <filesystem>
#include <string>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/run/StringsRun.hpp"

namespace fretbuzz {

// Writes into `dir` (created, replacing a previous run's files there) and returns it.
std::filesystem::path write_strings_outputs(const std::filesystem::path& dir, const StringsCase& sc, const StringsRun& run);

}  // namespace fretbuzz
