#include "fretbuzz/input/Score.hpp"

#include <algorithm>
#include <sstream>

#include "TomlSection.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/TextFile.hpp"

namespace fretbuzz {

namespace {
double in_range(TomlSection& s, std::string_view key, double fallback, double low, double high, const char* range) {
    const double v = s.number_or(key, fallback);
    if (!(v >= low && v <= high)) throw InputError(out_of_range_message(s.key_path(key), v, range));
    return v;
}

}  // namespace

double Score::end_s() const {
    double end = 0.0;
    for (const ScoreNote& n : notes) end = std::max(end, n.time_s + n.duration_s);
    return end;
}

void check_score_length(const Score& score, const std::string& source) {
    for (std::size_t i = 0; i < score.notes.size(); ++i) {
        const ScoreNote& n = score.notes[i];
        const double end = n.time_s + n.duration_s + score.tail_s;
        if (!(end <= kMaxScoreSeconds)) {
            std::ostringstream what;
            what << source << ": note[" << i << "] (at " << n.time_s << " s, lasting " << n.duration_s << " s) and the "
                 << score.tail_s << " s tail end at " << end << " s; a performance lasts at most " << kMaxScoreSeconds
                 << " s, tail included";
            throw InputError(what.str());
        }
    }
}

Score parse_note_list(std::string_view toml_text, const std::string& source_name) {
    const toml::table root = parse_toml_document(toml_text, source_name);
    TomlSection top(root, "");
    Score p;
    if (auto play = top.optional_section("play")) {
        p.tail_s = in_range(*play, "tail", p.tail_s, 0.0, 600.0, "[0, 600] s");
        p.strength_m_per_s = in_range(*play, "strength", p.strength_m_per_s, 0.0, 20.0, "[0, 20] m/s");
        p.width_m = in_range(*play, "width", p.width_m, 1e-4, 0.5, "[1e-4, 0.5] m");
        if (play->has("pickup")) p.pickup = in_range(*play, "pickup", 0.5, 0.0, 1.0, "(0, 1)");
        if (p.pickup == 0.0 || p.pickup == 1.0)
            throw InputError(out_of_range_message("play.pickup", p.pickup, "(0, 1)"));
        play->finish();
    }
    for (TomlSection& n : top.sections("note")) {
        ScoreNote note;
        note.time_s = in_range(n, "time", 0.0, 0.0, kMaxScoreSeconds, "[0, 3600] s");
        note.duration_s = in_range(n, "duration", note.duration_s, 0.0, 600.0, "[0, 600] s");
        note.fret = static_cast<int>(n.optional_count("fret", 0, kMaxFret).value_or(0));
        note.velocity = in_range(n, "velocity", note.velocity, 0.0, 1.0, "[0, 1]");
        note.position = in_range(n, "position", note.position, 0.01, 0.99, "[0.01, 0.99]");
        n.finish();
        p.notes.push_back(note);
    }
    top.finish();
    if (p.notes.empty()) throw InputError(source_name + ": note: at least one [[note]] is required");
    check_score_length(p, source_name);
    return p;
}

Score load_note_list(const std::filesystem::path& path) {
    return parse_note_list(read_text_file(path, "--notes", kMaxCaseFileBytes), path.string());
}

}  // namespace fretbuzz
