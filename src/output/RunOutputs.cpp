#include "fretbuzz/output/RunOutputs.hpp"

#include <optional>
#include <string>

#include "fretbuzz/output/AudioWriter.hpp"
#include "fretbuzz/output/CsvWriters.hpp"
#include "fretbuzz/output/Hdf5Writer.hpp"
#include "fretbuzz/output/OutputDirectory.hpp"
#include "fretbuzz/output/PolarisedAudio.hpp"
#include "fretbuzz/output/Provenance.hpp"
#include "fretbuzz/output/SummaryWriter.hpp"

namespace fretbuzz {

namespace {

std::vector<std::filesystem::path> staged_audio_paths(OutputDirectory& out, AudioSignal signal, const Case& c) {
    std::vector<std::filesystem::path> paths;
    for (const std::string& name : audio_file_names(signal, c.observation_points_m)) paths.push_back(out.staged(name));
    return paths;
}

// With two polarisations: audio_y*.wav (y alone) and, if a pickup angle is given,
// audio_pickup*.wav (the displacement along it).
std::vector<std::unique_ptr<PolarisedAudio>> polarised_audio(OutputDirectory& out, const Case& c,
                                                              const RunOutputOptions& o) {
    std::vector<std::unique_ptr<PolarisedAudio>> writers;
    if (!c.two_polarisations()) return writers;
    const auto add = [&](const std::string& stem, double angle) {
        std::vector<std::filesystem::path> paths;
        for (const std::string& name : polarised_audio_file_names(stem, c.observation_points_m))
            paths.push_back(out.staged(name));
        writers.push_back(std::make_unique<PolarisedAudio>(std::move(paths), c.run.audio_rate_hz, angle, o.fades));
    };
    add("audio_y", 90.0);
    if (c.polarisation.pickup_angle_given) add("audio_pickup", c.polarisation.pickup_angle_deg);
    return writers;
}

SummaryExtras summary_extras(const RunOutputOptions& o, const AudioWriter& audio,
                             const std::optional<AudioWriter>& velocity_audio,
                             const std::vector<std::unique_ptr<PolarisedAudio>>& polarised) {
    SummaryExtras extras{current_provenance(o.command_line.empty() ? "(library call)" : o.command_line), {&audio}};
    if (velocity_audio) extras.audio.push_back(&*velocity_audio);
    for (const auto& p : polarised) extras.audio.push_back(&p->writer());
    return extras;
}

}  // namespace

// Member order is construction order: the directory first, so every writer writes into it;
// the audio writers before the results and summary, which record their gains.
struct RunOutputs::Writers {
    Writers(const std::filesystem::path& dir, const Case& c, const RunOutputOptions& o)
        : out(dir),
          observation(out.staged("observation.csv")),
          energy(out.staged("energy.csv")),
          bridge_force(out.staged("bridge_force.csv")),
          audio(staged_audio_paths(out, AudioSignal::displacement, c), c.run.audio_rate_hz, AudioSignal::displacement,
                o.fades),
          velocity_audio(o.velocity_audio ? std::make_optional<std::vector<std::filesystem::path>>(
                                                staged_audio_paths(out, AudioSignal::velocity, c))
                                          : std::nullopt,
                         c.run.audio_rate_hz, o.fades),
          polarised(polarised_audio(out, c, o)),
          results(out.staged("results.h5"),
                  {.snapshot_rate_hz = o.snapshot_rate_hz,
                   .snapshot_until_s = o.snapshot_until_s,
                   .dense_contact_map = o.dense_contact_map,
                   .extras = summary_extras(o, audio, velocity_audio.writer, polarised)}),
          summary(out.staged("summary.json"), summary_extras(o, audio, velocity_audio.writer, polarised)) {}
    // The velocity WAVs, when asked for.
    struct OptionalAudio {
        OptionalAudio(std::optional<std::vector<std::filesystem::path>> paths, double rate, const AudioFades& fades) {
            if (paths) writer.emplace(std::move(*paths), rate, AudioSignal::velocity, fades);
        }
        std::optional<AudioWriter> writer;
    };
    OutputDirectory out;
    ObservationCsvWriter observation;
    EnergyCsvWriter energy;
    BridgeForceCsvWriter bridge_force;
    AudioWriter audio;
    OptionalAudio velocity_audio;
    std::vector<std::unique_ptr<PolarisedAudio>> polarised;
    Hdf5Writer results;
    SummaryWriter summary;
};

RunOutputs::RunOutputs(const std::filesystem::path& dir, const Case& c, const RunOutputOptions& options)
    : writers_(std::make_unique<Writers>(dir, c, options)) {
    Writers& w = *writers_;
    // Observers finish in this order: the WAVs (and their gains) before results and summary.
    observers_ = {&w.observation, &w.energy, &w.audio};
    if (w.velocity_audio.writer) observers_.push_back(&*w.velocity_audio.writer);
    for (const auto& p : w.polarised) observers_.push_back(p.get());
    observers_.insert(observers_.end(), {&w.results, &w.summary, &w.bridge_force});
}

RunOutputs::~RunOutputs() = default;

void RunOutputs::commit() { writers_->out.commit(); }

const std::filesystem::path& RunOutputs::path() const { return writers_->out.path(); }

}  // namespace fretbuzz
