#include "fretbuzz/io/RunOutputs.hpp"

#include <optional>
#include <string>

#include "fretbuzz/io/AudioWriter.hpp"
#include "fretbuzz/io/CsvWriters.hpp"
#include "fretbuzz/io/Hdf5Writer.hpp"
#include "fretbuzz/io/OutputDirectory.hpp"
#include "fretbuzz/io/SummaryWriter.hpp"

namespace fretbuzz {

namespace {

std::vector<std::filesystem::path> staged_audio_paths(OutputDirectory& out, AudioSignal signal, const Case& c) {
    std::vector<std::filesystem::path> paths;
    for (const std::string& name : audio_file_names(signal, c.observation_points_m)) paths.push_back(out.staged(name));
    return paths;
}

}  // namespace

// Member order is construction order: the directory first, so every writer writes into it.
struct RunOutputs::Writers {
    Writers(const std::filesystem::path& dir, const Case& c, const RunOutputOptions& o)
        : out(dir),
          observation(out.staged("observation.csv")),
          energy(out.staged("energy.csv")),
          bridge_force(out.staged("bridge_force.csv")),
          audio(staged_audio_paths(out, AudioSignal::displacement, c), c.run.audio_rate_hz),
          results(out.staged("results.h5"),
                  {.snapshot_rate_hz = o.snapshot_rate_hz,
                   .snapshot_until_s = o.snapshot_until_s,
                   .dense_contact_map = o.dense_contact_map}),
          summary(out.staged("summary.json")) {
        if (o.velocity_audio)
            velocity_audio.emplace(staged_audio_paths(out, AudioSignal::velocity, c), c.run.audio_rate_hz,
                                   AudioSignal::velocity);
    }
    OutputDirectory out;
    ObservationCsvWriter observation;
    EnergyCsvWriter energy;
    BridgeForceCsvWriter bridge_force;
    AudioWriter audio;
    Hdf5Writer results;
    SummaryWriter summary;
    std::optional<AudioWriter> velocity_audio;
};

RunOutputs::RunOutputs(const std::filesystem::path& dir, const Case& c, const RunOutputOptions& options)
    : writers_(std::make_unique<Writers>(dir, c, options)) {
    Writers& w = *writers_;
    observers_ = {&w.observation, &w.energy, &w.audio, &w.results, &w.summary, &w.bridge_force};
    if (w.velocity_audio) observers_.push_back(&*w.velocity_audio);
}

RunOutputs::~RunOutputs() = default;

void RunOutputs::commit() { writers_->out.commit(); }

const std::filesystem::path& RunOutputs::path() const { return writers_->out.path(); }

}  // namespace fretbuzz
