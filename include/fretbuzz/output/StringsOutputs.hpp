#pragma once
// The files of a run of strings on a bridge (simulate_strings), all or nothing: strings.csv (t,
// each string's energy by its name, the bridge's, the balance), written as the rows come;
// bridge.wav and bridge.ogg (the bridge's speed) and one pickup_<name>.wav per string; the
// case file as read; and summary.json (what report.html tabulates: the case, rates, steps, the
// strings' names, the balance named as a one-string run's). Nothing appears before commit().
#include <filesystem>
#include <memory>
#include <span>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/run/StringsRun.hpp"

namespace fretbuzz {

class StringsOutputs : public StringsObserver {
public:
    // Checks `dir` and stages its files (InputError naming --out if it cannot be written), for a
    // validated case.
    StringsOutputs(const std::filesystem::path& dir, const StringsCase& sc);
    ~StringsOutputs() override;  // discards the staged files unless commit() ran
    StringsOutputs(const StringsOutputs&) = delete;
    StringsOutputs& operator=(const StringsOutputs&) = delete;

    void row(std::span<const double> values) override;
    void audio(std::span<const double> frames) override;
    // After the run: the sound files and the summary, then the set in place at once.
    void commit(const StringsSummary& summary);
    const std::filesystem::path& path() const;

private:
    struct Files;
    std::unique_ptr<Files> files_;
};

}  // namespace fretbuzz
