#include "fretbuzz/output/StringsOutputs.hpp"

#include <nlohmann/json.hpp>

#include "fretbuzz/output/AudioWriter.hpp"
#include "fretbuzz/output/CsvWriters.hpp"
#include "fretbuzz/output/OutputDirectory.hpp"

namespace fretbuzz {

std::filesystem::path write_strings_outputs(const std::filesystem::path& dir, const StringsCase& sc, const StringsRun& run) {
    OutputDirectory out(dir);
    std::string text = "t";
    for (const std::string& name : sc.string_names) text += "," + name;
    text += ",bridge,balance\n";
    for (std::size_t r = 0; r < run.t.size(); ++r) {
        append_number(text, run.t[r]);
        for (const std::vector<double>& e : run.energy) {
            text += ',';
            append_number(text, e[r]);
        }
        text += ',';
        append_number(text, run.bridge_energy[r]);
        text += ',';
        append_number(text, run.balance[r]);
        text += '\n';
    }
    write_text_file(out.staged("strings.csv"), text);
    write_normalised_audio(out.staged("bridge.wav"), run.bridge_audio, run.audio_rate_hz);
    write_normalised_audio(out.staged("bridge.ogg"), run.bridge_audio, run.audio_rate_hz);  // to listen to, share
    for (std::size_t s = 0; s < sc.string_names.size(); ++s)
        write_normalised_audio(out.staged("pickup_" + sc.string_names[s] + ".wav"), run.pickup_audio[s], run.audio_rate_hz);
    write_text_file(out.staged("case.toml"), sc.source_text);
    // What report.html tabulates and how it finds each string's file.
    const nlohmann::ordered_json summary = {{"case", sc.name},
                                            {"fs", sc.run.sample_rate_hz},
                                            {"duration", sc.run.duration_s},
                                            {"steps", run.steps},
                                            {"output_rate", run.output_rate_hz},
                                            {"wall_seconds", run.wall_seconds},
                                            {"strings", sc.string_names},
                                            {"bridge_modes", sc.bridge.size()},
                                            {"worst_relative_balance", run.worst_balance}};
    write_text_file(out.staged("summary.json"), summary.dump(2) + "\n");
    out.commit();
    return out.path();
}

}  // namespace fretbuzz
