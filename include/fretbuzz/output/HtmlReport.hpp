#pragma once
// report.html: one self-contained page for a run's output directory, to open anywhere
// or send to someone: the figures `fretbuzz plot` drew, an audio player per WAV file,
// the run summary and the case file. Images, animation and audio are embedded as
// base64 data: URIs, so the page needs nothing beside it.
#include <filesystem>
#include <string>

namespace fretbuzz {

// The page for the output directory dir (reads summary.json, results.h5, *.png, *.wav).
std::string render_html_report(const std::filesystem::path& dir);
// Writes dir/report.html and returns its path.
std::filesystem::path write_html_report(const std::filesystem::path& dir);

// Escapes &, <, >, " and ' for HTML text and attribute values.
std::string html_escape(const std::string& text);

}  // namespace fretbuzz
