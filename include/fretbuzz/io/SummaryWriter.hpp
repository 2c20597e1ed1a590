#pragma once
// summary.json: what was run and how it went (energy balance, contacts, timing).
#include <filesystem>

#include "fretbuzz/run/RunObserver.hpp"

namespace fretbuzz {

class SummaryWriter : public RunObserver {
public:
    explicit SummaryWriter(const std::filesystem::path& path) : path_(path) {}
    void finish(const RunSummary& summary) override;

private:
    std::filesystem::path path_;
};

}  // namespace fretbuzz
