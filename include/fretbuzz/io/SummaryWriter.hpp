#pragma once
// summary.json: what was run and how it went (energy balance, contacts, timing).
#include <filesystem>
#include <string>
#include <vector>

#include "fretbuzz/run/RunObserver.hpp"

namespace fretbuzz {

// The summary as pretty-printed JSON text (also stored in results.h5 and given to Python).
std::string summary_json(const RunSummary& summary, const std::vector<double>& observation_points_m);

class SummaryWriter : public RunObserver {
public:
    explicit SummaryWriter(const std::filesystem::path& path) : path_(path) {}
    void begin(const RunLayout& layout) override { observation_points_m_ = layout.observation_points_m; }
    void finish(const RunSummary& summary) override;

private:
    std::filesystem::path path_;
    std::vector<double> observation_points_m_;
};

}  // namespace fretbuzz
