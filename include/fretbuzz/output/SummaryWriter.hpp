#pragma once
// summary.json: what was run and how it went (energy balance, contacts, timing), and,
// when written with a run's outputs, where it came from (provenance) and what full scale
// means in each WAV file.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "fretbuzz/output/Provenance.hpp"
#include "fretbuzz/run/RunObserver.hpp"

namespace fretbuzz {

class AudioWriter;

// What summary.json carries besides the RunSummary.
struct SummaryExtras {
    std::optional<Provenance> provenance{};  // with the case: "provenance"
    std::vector<const AudioWriter*> audio{};  // finished before the summary: "audio" (file, gain, fades)
};

// The summary as pretty-printed JSON text (also stored in results.h5 and given to Python).
// With `c` and `extras`, the provenance and audio blocks are added.
std::string summary_json(const RunSummary& summary, const std::vector<double>& observation_points_m,
                         const Case* c = nullptr, const SummaryExtras* extras = nullptr);

class SummaryWriter : public RunObserver {
public:
    explicit SummaryWriter(const std::filesystem::path& path, SummaryExtras extras = {})
        : path_(path), extras_(std::move(extras)) {}
    void begin(const RunLayout& layout) override {
        observation_points_m_ = layout.observation_points_m;
        case_ = layout.source;
    }
    void finish(const RunSummary& summary) override;

private:
    std::filesystem::path path_;
    SummaryExtras extras_;
    std::vector<double> observation_points_m_;
    const Case* case_ = nullptr;
};

}  // namespace fretbuzz
