#include "fretbuzz/output/StringsOutputs.hpp"

#include <nlohmann/json.hpp>

#include <memory>
#include <string>
#include <vector>

#include "CsvFile.hpp"
#include "StreamedAudio.hpp"
#include "fretbuzz/output/CsvWriters.hpp"
#include "fretbuzz/output/OutputDirectory.hpp"

namespace fretbuzz {

namespace {
constexpr double kMaxOggRateHz = 192000.0;

std::string strings_header(const StringsCase& sc) {
    std::string text = "t";
    for (const std::string& name : sc.string_names) text += "," + name;
    return text + ",bridge,balance\n";
}

// The bridge's sound, then each string's pickup, each in a scratch file of the staging folder.
std::vector<std::unique_ptr<StreamedAudio>> streamed_sounds(OutputDirectory& out, const StringsCase& sc) {
    std::vector<std::unique_ptr<StreamedAudio>> sounds;
    for (std::size_t k = 0; k <= sc.strings.size(); ++k)
        sounds.push_back(std::make_unique<StreamedAudio>(out.staged(".sound-" + std::to_string(k)), sc.run.audio_rate_hz));
    return sounds;
}
}  // namespace

struct StringsOutputs::Files {
    Files(const std::filesystem::path& dir, const StringsCase& c)
        : sc(c), out(dir), rows(out.staged("strings.csv"), strings_header(c), c.strings.size() + 3),
          sound(streamed_sounds(out, c)) {}

    const StringsCase& sc;
    OutputDirectory out;
    CsvFile rows;
    std::vector<std::unique_ptr<StreamedAudio>> sound;  // the bridge's, then each string's pickup
};

StringsOutputs::StringsOutputs(const std::filesystem::path& dir, const StringsCase& sc)
    : files_(std::make_unique<Files>(dir, sc)) {}

StringsOutputs::~StringsOutputs() = default;

void StringsOutputs::row(std::span<const double> values) { files_->rows.row(values); }

void StringsOutputs::audio(std::span<const double> frames) {
    const std::vector<std::unique_ptr<StreamedAudio>>& sound = files_->sound;
    const std::size_t width = sound.size();
    for (std::size_t k = 0; k + width <= frames.size(); k += width)
        for (std::size_t c = 0; c < width; ++c) sound[c]->push(frames[k + c]);
}

const std::filesystem::path& StringsOutputs::path() const { return files_->out.path(); }

void StringsOutputs::commit(const StringsSummary& run) {
    Files& f = *files_;
    const StringsCase& sc = f.sc;
    f.rows.close();
    f.sound[0]->write(f.out.staged("bridge.wav"));
    // To listen to, share: at the rates Vorbis encodes (libvorbis refuses 256 kHz and more).
    if (run.audio_rate_hz <= kMaxOggRateHz) f.sound[0]->write(f.out.staged("bridge.ogg"));
    for (std::size_t s = 0; s < sc.string_names.size(); ++s)
        f.sound[s + 1]->write(f.out.staged("pickup_" + sc.string_names[s] + ".wav"));
    write_text_file(f.out.staged("case.toml"), sc.source_text);
    // What report.html tabulates and how it finds each string's file; the balance under a
    // one-string run's keys.
    const nlohmann::ordered_json summary = {{"case", sc.name},
                                            {"fs", sc.run.sample_rate_hz},
                                            {"duration", sc.run.duration_s},
                                            {"steps", run.steps},
                                            {"output_rate", run.output_rate_hz},
                                            {"wall_seconds", run.wall_seconds},
                                            {"strings", sc.string_names},
                                            {"bridge_modes", sc.bridge.size()},
                                            {"max_relative_energy_increase", run.max_relative_energy_increase},
                                            {"max_relative_energy_balance_error", run.max_relative_balance_error}};
    write_text_file(f.out.staged("summary.json"), summary.dump(2) + "\n");
    f.out.commit();
}

}  // namespace fretbuzz
