#include "fretbuzz/output/HtmlReport.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/output/AudioWriter.hpp"
#include "fretbuzz/output/Base64.hpp"
#include "fretbuzz/output/CsvWriters.hpp"
#include "fretbuzz/output/Hdf5Writer.hpp"

namespace fretbuzz {

namespace fs = std::filesystem;

namespace {

struct Figure {
    const char* file;
    const char* id;
    const char* caption;
};

// The figures `fretbuzz plot` draws, in reading order.
constexpr Figure kFigures[] = {
    {"signal.png", "fig-signal",
     "Displacement at the first observation point, with zoomed windows, and the energy below it (as in Figure 2 "
     "of Issanchou et al. 2017)."},
    {"signal_all_points.png", "fig-signal-all", "Displacement at every observation point."},
    {"spectrogram.png", "fig-spectrogram", "Spectrogram of the displacement at the first observation point, 0-10 kHz "
                                           "(as in Figure 3)."},
    {"spectrogram_y.png", "fig-spectrogram-y", "Spectrogram of the second polarisation (y, parallel to the fretboard) "
                                               "at the first observation point."},
    {"orbit.png", "fig-orbit", "Orbit of the string at the first observation point: y against z over the zoomed "
                               "windows (two polarisations)."},
    {"energy.png", "fig-energy", "Energy of the string, its contact part, the energy dissipated so far, and the "
                                 "balance error."},
    {"contactogram.png", "fig-contactogram", "Contactogram: where (x) and when (t) the string touches the obstacle, "
                                             "coloured by the largest contact force in each output interval."},
    {"snapshots.png", "fig-snapshots", "String shapes over the obstacle at a few instants."},
    {"animation.gif", "fig-animation", "Animation of the string over the obstacle."},
    {"strings_energy.png", "fig-strings-energy", "Strings on a bridge: the energy of each string (its contacts and its "
                                                 "end's share with it) and of the bridge over time, the energy passing "
                                                 "between the strings; below, the balance of the whole assembly."},
};

std::string read_binary(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error("cannot read " + path.string());
    std::ostringstream bytes;
    bytes << in.rdbuf();
    return bytes.str();
}

std::string data_uri(const fs::path& path, const char* mime) {
    return std::string("data:") + mime + ";base64," + base64_encode(read_binary(path));
}

nlohmann::ordered_json read_summary(const fs::path& dir) {
    const fs::path path = dir / "summary.json";
    std::ifstream in(path);
    if (!in) throw InputError("DIR " + dir.string() + ": holds no summary.json (write one with `fretbuzz run CASE --out " +
                              dir.string() + "`)");
    try {
        return nlohmann::ordered_json::parse(in);
    } catch (const nlohmann::json::exception& e) {
        throw InputError("DIR " + dir.string() + ": summary.json is not valid JSON (" + e.what() + ")");
    }
}

std::string format_number(double v) {
    std::string text;
    append_number(text, v);
    return text;
}

void write_player(std::ostream& html, const fs::path& path, const std::string& caption) {
    html << "<figure class=\"audio\"><figcaption>" << html_escape(caption) << "</figcaption>\n<audio controls "
         << "preload=\"metadata\" src=\"" << data_uri(path, "audio/wav") << "\"></audio></figure>\n";
}

void write_audio_section(std::ostream& html, const fs::path& dir, const std::vector<double>& points) {
    html << "<section id=\"audio\"><h2>Listen</h2>\n";
    int players = 0;
    for (const AudioSignal signal : {AudioSignal::displacement, AudioSignal::velocity}) {
        const std::vector<std::string> names = audio_file_names(signal, points);
        for (std::size_t p = 0; p < names.size(); ++p) {
            const fs::path path = dir / names[p];
            if (!fs::is_regular_file(path)) continue;
            const char* what = signal == AudioSignal::velocity ? "Velocity (magnetic pickup)" : "Displacement";
            write_player(html, path, std::string(what) + " at x = " + format_number(points[p]) + " m (" + names[p] + ")");
            ++players;
        }
    }
    if (players == 0) html << "<p>No audio files in this directory.</p>\n";
    html << "</section>\n";
}

// A run of strings on a bridge: the bridge's sound, then each string's pickup.
void write_strings_audio_section(std::ostream& html, const fs::path& dir, const std::vector<std::string>& strings) {
    html << "<section id=\"audio\"><h2>Listen</h2>\n";
    if (fs::is_regular_file(dir / "bridge.wav"))
        write_player(html, dir / "bridge.wav", "The bridge's speed: the instrument's sound (bridge.wav)");
    for (const std::string& name : strings)
        if (const fs::path path = dir / ("pickup_" + name + ".wav"); fs::is_regular_file(path))
            write_player(html, path, "String " + name + " at its pickup (" + path.filename().string() + ")");
    html << "</section>\n";
}

void write_figures_section(std::ostream& html, const fs::path& dir) {
    html << "<section id=\"figures\"><h2>Figures</h2>\n";
    int shown = 0;
    for (const Figure& f : kFigures) {
        const fs::path path = dir / f.file;
        if (!fs::is_regular_file(path)) continue;
        const char* mime = path.extension() == ".gif" ? "image/gif" : "image/png";
        html << "<figure class=\"plot\" id=\"" << f.id << "\"><img alt=\"" << html_escape(f.caption) << "\" src=\""
             << data_uri(path, mime) << "\"><figcaption>" << html_escape(f.caption) << "</figcaption></figure>\n";
        ++shown;
    }
    if (const fs::path mp4 = dir / "animation.mp4"; fs::is_regular_file(mp4)) {
        html << "<figure class=\"plot\" id=\"fig-animation-video\"><video controls loop src=\"" << data_uri(mp4, "video/mp4")
             << "\"></video><figcaption>Animation of the string over the obstacle.</figcaption></figure>\n";
        ++shown;
    }
    if (shown == 0) html << "<p>No figures yet: run <code>fretbuzz plot " << html_escape(dir.string()) << "</code>.</p>\n";
    html << "</section>\n";
}

// The summary keys the report names in words, with their units ("" for none).
struct SummaryRow {
    const char* key;
    const char* label;
    const char* unit;
};
constexpr SummaryRow kSummaryRows[] = {
    {"case", "Case", ""},
    {"fs", "Sampling rate fs", "Hz"},
    {"duration", "Simulated duration", "s"},
    {"steps", "Time steps", ""},
    {"modes", "Modes", ""},
    {"modes_choice", "Why this many modes", ""},
    {"output_rate", "Output rate", "Hz"},
    {"wall_seconds", "Computing time", "s"},
    {"steps_per_second", "Speed", "steps/s"},
    {"lossless", "Lossless", ""},
    {"contact_screening", "Contact screening", ""},
    {"contact_screening_choice", "Why screening is on or off", ""},
    {"polarisations", "Polarisations", ""},
    {"fingers", "Fingers", ""},
    {"gestures", "Gestures (forces, plucks, pops, slaps)", ""},
    {"energy_initial_J", "Initial energy H(1/2)", "J"},
    {"energy_final_J", "Final energy", "J"},
    {"energy_z_final_J", "Final energy along z (with contact)", "J"},
    {"energy_y_final_J", "Final energy along y", "J"},
    {"finger_energy_final_J", "Final energy of the fingers and pluckers (kinetic and contact)", "J"},
    {"work_J", "Work done on the string by fingers, forces and pluckers", "J"},
    {"dissipated_J", "Energy dissipated, all losses", "J"},
    {"damping_dissipated_J", "Energy dissipated by damping", "J"},
    {"damping_z_J", "Energy dissipated by damping along z", "J"},
    {"damping_y_J", "Energy dissipated by damping along y", "J"},
    {"finger_loss_J", "Energy dissipated in the contacts of fingers and pluckers", "J"},
    {"friction_dissipated_J", "Energy dissipated by friction", "J"},
    {"max_relative_energy_increase", "Largest rise of the energy less the work put in, relative to max(H(1/2), work)", ""},
    {"max_relative_energy_balance_error", "Largest energy-balance error, relative to max(H(1/2), work)", ""},
    {"contact_steps", "Steps with contact (obstacle)", ""},
    {"finger_contact_steps", "Steps where a finger, force or plucker acted", ""},
    {"first_contact_s", "First contact (obstacle)", "s"},
    {"last_contact_s", "Last contact (obstacle)", "s"},
    {"max_newton_iterations", "Most Newton iterations in a step", ""},
    {"max_friction_iterations", "Most friction iterations in a step", ""},
    {"mean_points_solved_per_step", "Contact solves per step (mean)", ""},
    {"free_flight_fraction", "Share of steps in free flight", ""},
    {"observation_points_m", "Observation points", "m"},
    {"strings", "Strings on the bridge", ""},
    {"bridge_modes", "Bridge modes", ""},
    {"warnings", "Warnings", ""},
};

// Numbers to 4 significant digits, lists item by item, text as it is.
std::string rounded(const nlohmann::ordered_json& value) {
    if (value.is_string()) return value.get<std::string>();
    if (value.is_number_float()) {
        const double v = value.get<double>();
        // Whole digits are kept below 1e9 (400000 Hz, not 4e+05 Hz).
        const int digits = v != 0.0 && std::abs(v) < 1e9 ? static_cast<int>(std::floor(std::log10(std::abs(v)))) + 1 : 0;
        std::ostringstream text;
        text.precision(std::max(4, digits));
        text << v;
        return text.str();
    }
    if (value.is_array()) {
        std::string list;
        for (const auto& item : value) list += (list.empty() ? "" : item.is_string() ? "; " : ", ") + rounded(item);
        return list.empty() ? "none" : list;
    }
    return value.dump();
}

void write_row(std::ostream& html, const std::string& label, const std::string& value, const std::string& unit) {
    html << "<tr><th>" << html_escape(label) << "</th><td>" << html_escape(value) << (unit.empty() ? "" : " ")
         << html_escape(unit) << "</td></tr>\n";
}

void write_summary_section(std::ostream& html, const nlohmann::ordered_json& summary) {
    html << "<section id=\"summary\"><h2>Run summary</h2>\n<table id=\"summary-table\">\n";
    std::vector<std::string> named;
    for (const SummaryRow& row : kSummaryRows) {
        named.emplace_back(row.key);
        if (summary.contains(row.key)) write_row(html, row.label, rounded(summary[row.key]), row.unit);
    }
    // Keys this page has no words for yet: shown under their own names.
    for (const auto& [key, value] : summary.items())
        if (std::find(named.begin(), named.end(), key) == named.end() && key != "provenance" && key != "audio")
            write_row(html, key, rounded(value), "");
    html << "</table></section>\n";
}

// Where the results come from, and what full scale means in each WAV file.
void write_provenance_section(std::ostream& html, const nlohmann::ordered_json& summary) {
    if (summary.contains("audio")) {
        html << "<section id=\"audio-gain\"><h2>Audio files</h2>\n<table id=\"audio-table\">\n"
                "<tr><th>file</th><th>signal at x</th><th>full scale</th><th>fade in / out</th></tr>\n";
        for (const auto& a : summary["audio"])
            html << "<tr><td>" << html_escape(a.value("file", std::string())) << "</td><td>"
                 << html_escape(a.value("signal", std::string())) << " at " << rounded(a.value("x_m", nlohmann::ordered_json()))
                 << " m</td><td>" << rounded(a.value("full_scale", nlohmann::ordered_json())) << " "
                 << html_escape(a.value("full_scale_unit", std::string())) << "</td><td>"
                 << rounded(a.value("fade_in_s", nlohmann::ordered_json())) << " s / "
                 << rounded(a.value("fade_out_s", nlohmann::ordered_json())) << " s</td></tr>\n";
        html << "</table><p>A sample of 1.0 (full scale) in a file stands for the value given.</p></section>\n";
    }
    if (!summary.contains("provenance")) return;
    const auto& p = summary["provenance"];
    html << "<section id=\"provenance\"><h2>Provenance</h2>\n<table id=\"provenance-table\">\n";
    write_row(html, "fretbuzz version", p.value("fretbuzz_version", std::string()), "");
    write_row(html, "Run on (UTC)", p.value("created_utc", std::string()), "");
    write_row(html, "Command line", p.value("command_line", std::string()), "");
    write_row(html, "Platform", p.value("platform", std::string()), "");
    write_row(html, "Case file SHA-256", p.value("case_sha256", std::string()), "");
    if (p.contains("mode_table") && p["mode_table"].contains("frequency_hz")) {
        const auto& f = p["mode_table"]["frequency_hz"];
        if (!f.empty())
            write_row(html, "Mode table", std::to_string(f.size()) + " modes, " + rounded(f.front()) + " to " +
                                              rounded(f.back()) + " Hz (in results.h5 /modes)", "");
    }
    html << "</table></section>\n";
}

void write_case_section(std::ostream& html, const fs::path& dir) {
    const fs::path results = dir / "results.h5";
    if (const fs::path written = dir / "case.toml"; !fs::is_regular_file(results) && fs::is_regular_file(written)) {
        html << "<section id=\"case\"><h2>Case file</h2>\n<pre>" << html_escape(read_binary(written)) << "</pre></section>\n";
        return;
    }
    if (!fs::is_regular_file(results)) return;
    html << "<section id=\"case\"><h2>Case file</h2>\n<pre>" << html_escape(read_case_text(results)) << "</pre></section>\n";
}

constexpr const char* kStyle = R"(body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222}
h1{font-size:1.6em}figure{margin:1.5em 0}figure.plot img,figure.plot video{max-width:100%;border:1px solid #ddd}
figcaption{color:#555;font-size:.9em;margin-top:.3em}audio{width:100%;max-width:600px}
table{border-collapse:collapse}th,td{border-bottom:1px solid #eee;padding:.2em .8em;text-align:left;font-size:.9em}
th{font-weight:600}pre{background:#f6f6f6;padding:1em;overflow-x:auto;font-size:.85em})";

}  // namespace

std::string html_escape(const std::string& text) {
    std::string out;
    out.reserve(text.size());
    for (const char ch : text) {
        switch (ch) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            case '\'': out += "&#39;"; break;
            default: out += ch;
        }
    }
    return out;
}

std::string render_html_report(const fs::path& dir) {
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) throw InputError("DIR " + dir.string() + ": no such directory");
    const nlohmann::ordered_json summary = read_summary(dir);
    const std::string case_name = summary.value("case", std::string("(unnamed case)"));
    std::vector<double> points;
    if (summary.contains("observation_points_m")) points = summary["observation_points_m"].get<std::vector<double>>();

    std::ostringstream html;
    html << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>fretbuzz: "
         << html_escape(case_name) << "</title>\n<style>" << kStyle << "</style></head>\n<body>\n<h1 id=\"title\">fretbuzz: "
         << html_escape(case_name) << "</h1>\n";
    if (summary.contains("strings"))
        write_strings_audio_section(html, dir, summary["strings"].get<std::vector<std::string>>());
    else
        write_audio_section(html, dir, points);
    write_figures_section(html, dir);
    write_summary_section(html, summary);
    write_provenance_section(html, summary);
    write_case_section(html, dir);
    html << "</body></html>\n";
    return html.str();
}

fs::path write_html_report(const fs::path& dir) {
    const std::string page = render_html_report(dir);
    const fs::path path = dir / "report.html";
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out << page;
    out.close();
    if (!out) throw std::runtime_error("cannot write " + path.string());
    return path;
}

}  // namespace fretbuzz
