// `fretbuzz setup INSTRUMENT --out DIR`: the set-up bench. Plays every note of every string
// of an instrument at each attack (setup/BuzzMap), with what-ifs applied first
// (setup/WhatIf), and writes the buzz map (CSV, map.json, a WAV per note, buzz_map.html drawn
// by the Python package's template), the comparison with an earlier map and the advice.
// This file only reads the options and hands over to the library.
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <memory>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "../Commands.hpp"
#include "../PythonScript.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/InstrumentFile.hpp"
#include "fretbuzz/input/InstrumentUnits.hpp"
#include "fretbuzz/output/OutputDirectory.hpp"
#include "fretbuzz/setup/Advice.hpp"
#include "fretbuzz/setup/BuzzMap.hpp"
#include "fretbuzz/setup/Calibration.hpp"
#include "fretbuzz/setup/FretDress.hpp"
#include "fretbuzz/setup/MapFiles.hpp"
#include "fretbuzz/setup/WhatIf.hpp"

namespace fretbuzz::cli {

namespace {

struct SetupArguments {
    std::string instrument, out;
    std::string strength, compare, strings, frets, jobs, ensemble, fs, duration;  // strength "": soft,medium,hard
    std::string calibrate, player;
    std::string tolerate, dress_depth, crown, fall_away, listen, partial_scatter;
    WhatIfWords what_if;
    bool finger = false, advice = false, dress = false, quiet = false, stiffness_check = false, no_clean_up_to = false;
};

std::vector<std::string> split(const std::string& text, char separator) {
    std::vector<std::string> parts;
    std::size_t start = 0;
    while (start <= text.size()) {
        const std::size_t at = text.find(separator, start);
        parts.push_back(text.substr(start, at == std::string::npos ? std::string::npos : at - start));
        start = at == std::string::npos ? text.size() + 1 : at + 1;
    }
    return parts;
}

// "0-20", "0,5,7", "12": frets in [0, last].
std::vector<std::size_t> parse_frets(const std::string& text, std::size_t last) {
    std::vector<std::size_t> frets;
    const std::string what = "a fret (0: the open string, up to the last fret, " + std::to_string(last) + ")";
    for (const std::string& part : split(text, ',')) {
        const std::size_t dash = part.find('-', 1);
        const std::size_t a = whole_number(part.substr(0, dash), "--frets", 0, last, what);
        const std::size_t b = dash == std::string::npos ? a : whole_number(part.substr(dash + 1), "--frets", a, last, what);
        for (std::size_t k = a; k <= b; ++k)
            if (std::find(frets.begin(), frets.end(), k) == frets.end()) frets.push_back(k);
    }
    std::sort(frets.begin(), frets.end());
    return frets;
}

void apply_settings(const SetupArguments& a, Instrument& instrument) {
    if (!a.ensemble.empty())
        instrument.attack.ensemble = whole_number(a.ensemble, "--ensemble", 1, 200, "the most plucks per note");
    if (!a.fs.empty()) {
        const double fs = parse_quantity_or(a.fs, Quantity::frequency, "Hz", "--fs");
        if (!(fs >= 5e4 && fs <= 2e7)) throw InputError(out_of_range_message("--fs (Hz)", fs, "must be in [50000, 2e7]"));
        instrument.bench.sample_rate_hz = fs;
    }
    if (!a.duration.empty()) {
        const double d = parse_quantity_or(a.duration, Quantity::time, "s", "--duration");
        if (!(d >= 0.01 && d <= 5.0)) throw InputError(out_of_range_message("--duration (s)", d, "must be in [0.01, 5]"));
        instrument.bench.duration_s = d;
    }
    if (!a.partial_scatter.empty()) {
        // Not a number reads as NaN, which the range refuses, naming it.
        const std::string& text = a.partial_scatter;
        double cents = std::numeric_limits<double>::quiet_NaN();
        if (const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), cents);
            error != std::errc() || end != text.data() + text.size())
            cents = std::numeric_limits<double>::quiet_NaN();
        instrument.bench.partial_scatter_cents = checked_partial_scatter(cents, "--partial-scatter");
    }
    if (!a.listen.empty()) instrument.bench.listen_through_rig = listens_through_rig(a.listen, "--listen");
}

std::string clock(double seconds) {
    char text[32];
    const long s = static_cast<long>(seconds + 0.5);
    std::snprintf(text, sizeof text, "%ld:%02ld", s / 60, s % 60);
    return text;
}

std::string verdict_text(const NoteVerdict& v) {
    if (v.status != "ok") return v.status + (v.buzz_fret > 0 ? " against fret " + std::to_string(v.buzz_fret) : "");
    char text[128];
    std::snprintf(text, sizeof text, "%s, %zu/%zu plucks buzz", v.verdict.c_str(),
                  static_cast<std::size_t>(v.buzz_fraction * static_cast<double>(v.plucks) + 0.5), v.plucks);
    std::string out = text;
    if (std::isfinite(v.buzz_db)) {
        std::snprintf(text, sizeof text, ", median %+.0f dB over the masked threshold", v.buzz_db);
        out += text;
    }
    if (v.buzz_fret > 0 && v.buzz_fraction > 0.0) out += " (fret " + std::to_string(v.buzz_fret) + ")";
    if (std::isfinite(v.first_touch_s)) {
        std::snprintf(text, sizeof text, ", first touch at %.0f ms", v.first_touch_s * 1e3);
        out += text;
    }
    if (std::isinf(v.clean_up_to)) {
        std::snprintf(text, sizeof text, "; clean up to at least %gx", kCleanUpToCap);
        out += text;
    } else if (std::isfinite(v.clean_up_to)) {
        std::snprintf(text, sizeof text, "; clean up to %.2fx (%.3g %s)", v.clean_up_to, v.clean_up_to_value, v.unit.c_str());
        out += text;
    }
    return out;
}

// --calibrate: the attack scale that explains what the player hears, on the instrument as it is
// (so no what-if, and the report's rows say which notes and attacks).
int calibrate_command(const SetupArguments& a) {
    const bool shaped = !a.strength.empty() || !a.compare.empty() || !a.strings.empty() || !a.frets.empty() || a.advice ||
                        a.dress || !a.tolerate.empty() || a.stiffness_check || a.no_clean_up_to || !a.what_if.words().empty();
    if (!a.player.empty())
        throw InputError("--calibrate finds the player's attack scale and --player applies one: give one of them");
    if (shaped)
        throw InputError("--calibrate plays the report's notes (its string, fret and strength columns) on the instrument "
                         "as it is: give it without what-ifs, --strength, --strings, --frets, --compare, --advice, --dress, "
                         "--tolerate, --stiffness-check or --no-clean-up-to");
    Instrument instrument = load_instrument(a.instrument);
    for (const std::string& w : instrument.warnings) std::cerr << "fretbuzz: warning: " << w << "\n";
    apply_settings(a, instrument);
    describe_geometry(instrument);
    const std::vector<HeardNote> report = read_player_report(a.calibrate, instrument);
    CalibrationRequest request;
    request.finger = a.finger;
    if (!a.jobs.empty()) request.jobs = static_cast<unsigned>(whole_number(a.jobs, "--jobs", 1, 256, "the thread count"));
    OutputDirectory out(a.out);
    const bool terminal = ::isatty(STDERR_FILENO) != 0;
    if (!a.quiet)
        request.on_note = [&](const NoteVerdict& v, std::size_t done, std::size_t total) {
            std::cerr << (terminal ? "\r\033[K" : "") << "fretbuzz: calibrating " << done << "/" << total << " "
                      << v.string_name << " fret " << v.fret << " " << v.strength << ": " << verdict_text(v)
                      << (terminal ? "" : "\n") << std::flush;
        };
    Calibration calibration;
    try {
        calibration = calibrate_attack(instrument, report, request);
    } catch (const Interrupted& e) {
        std::cerr << "\nfretbuzz: " << e.what() << ": nothing was written to " << a.out << "\n";
        return 128 + e.signal();
    }
    if (!a.quiet && terminal) std::cerr << "\n";
    std::ofstream(out.staged("calibration.json")) << calibration_json(calibration, instrument, a.calibrate, command_line())
                                                  << "\n";
    throw_if_stopped();
    out.commit();
    std::cerr << calibration_text(calibration) << "fretbuzz: " << report.size() << " rows, "
              << calibration.plucks_simulated << " plucks simulated in " << std::fixed << std::setprecision(1)
              << calibration.wall_seconds << " s; " << a.out << "/calibration.json\n";
    return 0;
}

int setup_command(const SetupArguments& a) {
    stop_cleanly_on_signals();
    if (!a.calibrate.empty()) return calibrate_command(a);
    Instrument instrument = load_instrument(a.instrument);
    for (const std::string& w : instrument.warnings) std::cerr << "fretbuzz: warning: " << w << "\n";
    apply_settings(a, instrument);
    const Instrument as_found = instrument;
    const WhatIfReading what_if = read_what_ifs(a.what_if, instrument);
    for (const std::string& value : what_if.as_read) std::cerr << "fretbuzz: " << value << "\n";
    instrument = apply_change(instrument, what_if.change);
    if (const auto pull = pull_change(as_found, instrument))
        std::cerr << std::fixed << std::setprecision(1) << "fretbuzz: the strings pull " << pull->after_n << " N (" << pull->before_n
                  << " N when the relief was set): the neck bows " << std::setprecision(3) << std::abs(pull->bow_m) * 1e3
                  << " mm " << (pull->bow_m > 0.0 ? "more" : "less") << "; relief at fret " << pull->fret << ": "
                  << pull->relief_before_m * 1e3 << " -> " << pull->relief_after_m * 1e3 << " mm\n"
                  << std::defaultfloat;
    describe_geometry(instrument);  // every string clear of its frets, before anything runs
    MapRequest request;
    request.attacks = parse_attacks(a.strength.empty() ? "soft,medium,hard" : a.strength, instrument.attack);
    // The player's touch: every attack's size, and so the advice's and the dress's, scaled.
    std::optional<PlayerTouch> touch;
    if (!a.player.empty()) {
        touch = read_player_touch(a.player);
        scale_attacks(request.attacks, touch->attack_scale);
        std::cerr << "fretbuzz: the attacks calibrated to the player: " << touch->attack_scale << " x their size ("
                  << a.player << ")\n";
    }
    request.finger = a.finger;
    request.stiffness_check = a.stiffness_check;
    request.clean_up_to = !a.no_clean_up_to;
    if (!a.jobs.empty()) request.jobs = static_cast<unsigned>(whole_number(a.jobs, "--jobs", 1, 256, "the thread count"));
    if (!a.strings.empty())
        for (const std::string& name : split(a.strings, ',')) request.strings.push_back(instrument.string_index(name));
    if (!a.frets.empty()) request.frets = parse_frets(a.frets, instrument.neck.fret_count);
    map_notes(instrument, request);
    // What the advice and the dress answer for, checked before anything runs.
    AdviceRequest advice_request;
    advice_request.attack = request.attacks.back();
    advice_request.finger = a.finger;
    advice_request.jobs = request.jobs;
    advice_request.strings = request.strings;
    advice_request.frets = request.frets;
    advice_request.tolerate = tolerance_for(instrument, a.tolerate);
    DressRequest dress_request;
    dress_request.play = advice_request;
    if (!a.dress_depth.empty())
        dress_request.max_depth_m = parse_quantity_or(a.dress_depth, Quantity::length, "mm", "--dress-depth");
    if (!a.crown.empty()) dress_request.min_crown_m = parse_quantity_or(a.crown, Quantity::length, "mm", "--crown");
    if (!a.fall_away.empty())
        dress_request.fall_away_from = whole_number(a.fall_away, "--fall-away", 1, instrument.neck.fret_count,
                                                    "the fret the fall-away starts from");
    if (a.dress) check_dress_request(instrument, dress_request);
    if ((!a.dress_depth.empty() || !a.crown.empty() || !a.fall_away.empty()) && !a.dress)
        throw InputError("--dress-depth, --crown and --fall-away shape the fret dress: give --dress with them");
    if (!a.tolerate.empty() && !a.dress && !a.advice)
        throw InputError("--tolerate says what the advice and the dress may let buzz: give --advice or --dress with it");
    std::vector<NoteVerdict> before;
    if (!a.compare.empty()) before = read_buzz_map_csv(std::filesystem::path(a.compare) / "buzz_map.csv", "--compare");

    OutputDirectory out(a.out);
    const std::filesystem::path staging = out.staged("buzz_map.csv").parent_path();
    request.audio_dir = staging;
    const bool terminal = ::isatty(STDERR_FILENO) != 0;
    const auto started = std::chrono::steady_clock::now();
    if (!a.quiet)
        request.on_note = [&](const NoteVerdict& v, std::size_t done, std::size_t total) {
            const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
            std::cerr << (terminal ? "\r\033[K" : "") << "fretbuzz: " << done << "/" << total << " " << v.string_name
                      << " fret " << v.fret << " " << v.strength << ": " << verdict_text(v) << ", ETA "
                      << clock(elapsed / static_cast<double>(done) * static_cast<double>(total - done))
                      << (terminal ? "" : "\n") << std::flush;
        };
    BuzzMapResult map;
    try {
        map = play_map(instrument, request);
    } catch (const Interrupted& e) {
        std::cerr << "\nfretbuzz: " << e.what() << ": the map is lost (the bench keeps no partial map) and nothing was "
                  << "written to " << a.out << "; run the command again to compute it\n";
        return 128 + e.signal();
    }
    if (!a.quiet && terminal) std::cerr << "\n";
    for (const NoteVerdict& v : map.notes)
        if (!v.audio.empty()) out.staged(v.audio);

    MapDocument doc;
    doc.command = command_line();
    doc.changes = a.what_if.words();
    doc.attacks = request.attacks;
    doc.finger = a.finger;
    if (touch) {
        doc.player_file = touch->file.string();
        doc.attack_scale = touch->attack_scale;
    }
    doc.notes = map.notes;
    doc.wall_seconds = map.wall_seconds;
    write_buzz_map_csv(out.staged("buzz_map.csv"), map.notes);
    if (!a.compare.empty()) {
        doc.comparison = compare_maps(map.notes, before);
        doc.compared_with = a.compare;
        write_comparison_csv(out.staged("compare.csv"), doc.comparison);
    }
    // On a terminal a search says what it has played (it has no total to count down).
    const auto search_progress = [&](const std::string& what) -> std::function<void(const NoteVerdict&, std::size_t)> {
        if (a.quiet || !terminal) return {};
        return [what, played = std::size_t{0}](const NoteVerdict& v, std::size_t probes) mutable {
            std::cerr << "\r\033[K" << "fretbuzz: " << what << ": " << ++played << " notes played in " << probes
                      << " probes; the last, " << v.string_name << " fret " << v.fret << ": " << verdict_text(v)
                      << std::flush;
        };
    };
    if (a.advice) {
        if (!a.quiet) std::cerr << "fretbuzz: advice: searching (each probe plays notes at the "
                                << advice_request.attack.label << " attack)\n";
        advice_request.on_note = search_progress("advice");
        const Advice advice = advise(instrument, map.notes, advice_request);
        if (advice_request.on_note) std::cerr << "\n";
        doc.advice_json = advice_json(advice);
        std::ofstream(out.staged("advice.json")) << doc.advice_json << "\n";
        std::ofstream(out.staged("advice.txt")) << advice_text(advice);
        if (!a.quiet) std::cerr << advice_text(advice);
    }
    if (a.dress) {
        if (!a.quiet) std::cerr << "fretbuzz: fret dress: searching at the " << advice_request.attack.label << " attack\n";
        dress_request.play.on_note = search_progress("fret dress");
        const DressResult dress = dress_frets(instrument, map.notes, dress_request);
        if (dress_request.play.on_note) std::cerr << "\n";
        doc.dress_json = dress_json(dress);
        doc.dressed_notes = dress.after;
        std::ofstream(out.staged("dress.csv")) << dress_csv(dress);
        std::ofstream(out.staged("dress.json")) << doc.dress_json << "\n";
        std::ofstream(out.staged("dress.txt")) << dress_text(dress);
        write_buzz_map_csv(out.staged("dress_map.csv"), dress.after);
        if (!a.quiet) std::cerr << dress_text(dress);
    }
    write_map_json(out.staged("map.json"), instrument, doc);
    // The page is drawn by the Python package; without it the map is still whole (CSV, JSON, WAVs).
    int drawn = 1;
    try {
        drawn = run_package_main("setup_report", {staging.string(), "--out", out.staged("buzz_map.html").string()});
    } catch (const std::runtime_error& e) {
        std::cerr << "fretbuzz: warning: " << e.what() << "\n";
    }
    throw_if_stopped();  // interrupted while the page was drawn: nothing is committed (exit 130 or 143)
    if (drawn != 0)
        std::cerr << "fretbuzz: warning: buzz_map.html was not drawn (the Python package fretbuzz with Jinja2 is needed: "
                     "apt-get install python3-jinja2); the map is in buzz_map.csv and map.json, draw it later with "
                     "`python3 -m fretbuzz.setup_report "
                  << a.out << "`\n";
    out.commit();
    std::size_t buzzing = 0, marginal = 0;
    for (const NoteVerdict& v : map.notes) {
        buzzing += v.verdict == "buzzes";
        marginal += v.verdict == "marginal";
    }
    std::cerr << "fretbuzz: " << map.notes.size() << " notes (" << buzzing << " buzz, " << marginal << " marginal; "
              << map.plucks_simulated << " plucks simulated, " << map.plucks_clear << " clear of every fret) on "
              << map.jobs << " threads in " << std::fixed << std::setprecision(1) << map.wall_seconds << " s; map in "
              << a.out << "/buzz_map.html and buzz_map.csv\n";
    return 0;
}

}  // namespace

void add_setup_command(CLI::App& app, Action& action) {
    auto args = std::make_shared<SetupArguments>();
    CLI::App* cmd = app.add_subcommand(
        "setup", "Set-up bench: the buzz map of every note of every string of an instrument, what-ifs and advice");
    cmd->add_option("instrument", args->instrument,
                    "A built-in instrument (jazz-bass, electric-guitar, bass-5, bass-neck) or an instrument file (.toml, see "
                    "docs/instrument-format.md)")
        ->required();
    cmd->add_option("--out", args->out, "Output directory: buzz_map.html, buzz_map.csv, map.json, note-*.wav")->required();
    cmd->add_option("--strength", args->strength,
                    "Attacks: soft,medium,hard (finger plucks, the default), pick, pop, slap, a finger pluck's amplitude "
                    "(1.2mm) or a slap's speed (3m/s)");
    // Lengths: with a unit (mm, in, 3/32in, 5/64", 12thou), or bare in the instrument file's units.
    WhatIfWords& w = args->what_if;
    cmd->add_option("--relief", w.relief,
                    "What-if: the truss rod set for this relief gap (under the first string, at the relief fret; a "
                    "length: mm, in, 12thou, or bare in the instrument file's units)");
    cmd->add_option("--relief-change", w.relief_change,
                    "What-if: the truss rod turned so that the relief gap changes by this much (+0.002in: looser; after "
                    "--set and --tune)");
    cmd->add_option("--truss-rod-turns", w.truss_rod_turns,
                    "What-if: the truss rod turned this much (+1/4: a quarter turn clockwise, tighter, less relief; "
                    "needs adjusters.truss_rod_turn in the instrument file)");
    cmd->add_option("--action12", w.action12, "What-if: STRING=LENGTH, that string's gap over fret 12 (repeatable)")
        ->allow_extra_args(false);
    cmd->add_option("--action", w.action,
                    "What-if: FRET:STRING=LENGTH (17:E=3/32in), that string's gap over that fret: its saddle raised or "
                    "lowered, nut and neck held, by about scale/(fret's distance from the nut) times the gap's change "
                    "(repeatable)")
        ->allow_extra_args(false);
    cmd->add_option("--nut", w.nut, "What-if: STRING=LENGTH, that string's gap over fret 1 (repeatable)")
        ->allow_extra_args(false);
    cmd->add_option("--nut-change", w.nut_change,
                    "What-if: STRING=LENGTH, that string's nut slot lowered (-, filed) or raised (+, shimmed) by this "
                    "much (repeatable)")
        ->allow_extra_args(false);
    cmd->add_option("--saddle", w.saddle,
                    "What-if: STRING=LENGTH, that string's saddle height above the fret plane (repeatable)")
        ->allow_extra_args(false);
    cmd->add_option("--saddle-change", w.saddle_change,
                    "What-if: STRING=LENGTH, that string's saddle raised (+) or lowered (-) by this much, e.g. "
                    "E=-0.25mm (repeatable)")
        ->allow_extra_args(false);
    cmd->add_option("--saddle-turns", w.saddle_turns,
                    "What-if: STRING=TURNS, that saddle's height screws turned (+ clockwise: up), e.g. E=-1/2; needs "
                    "adjusters.saddle_screw_pitch in the instrument file (repeatable)")
        ->allow_extra_args(false);
    cmd->add_option("--fret-offset", w.fret_offsets,
                    "What-if: K=LENGTH raises (or, negative, lowers) fret K; K=level dresses it to its neighbours "
                    "(repeatable)")
        ->allow_extra_args(false);
    cmd->add_option("--tune", w.tune,
                    "What-if: STRING=PITCH retunes that string (a note or Hz, e.g. E=D2 for drop D; repeatable); the neck "
                    "bows with the strings' pull")
        ->allow_extra_args(false);
    cmd->add_option("--set", w.string_set,
                    "What-if: the strings replaced by a named set's at the same pitches (cases/strings/sets.toml); the "
                    "neck bows with the strings' pull");
    cmd->add_option("--calibrate", args->calibrate,
                    "REPORT.csv (string,fret,heard[,strength]; heard: buzz or clean): find the attack scale that "
                    "explains what the player hears on the instrument as it is; writes DIR/calibration.json");
    cmd->add_option("--player", args->player,
                    "A calibration.json (--calibrate): every attack's size times its attack_scale, in (0, 10]");
    cmd->add_flag("--finger", args->finger, "Stopped notes by the finger model (slow) instead of the stand-in");
    cmd->add_option("--compare", args->compare, "An earlier map's --out: mark the notes that changed");
    cmd->add_option("--strings", args->strings, "Strings to play, by name (e.g. E,A; default: all)");
    cmd->add_option("--frets", args->frets, "Frets to play, e.g. 0-20 or 0,5,7 (default: every one)");
    cmd->add_flag("--advice", args->advice,
                  "Also search, at the last attack of --strength, the lowest clean action per string (and the saddle "
                  "move to it), where a fall-away would help, the proud frets and the relief with the least buzz");
    cmd->add_option("--tolerate", args->tolerate,
                    "What the advice and the dress may let buzz: marginal (marginal notes pass), above=K (notes above "
                    "fret K), both (marginal,above=15), or none; default as set-ups do: marginal notes, and on a bass "
                    "the notes above fret 15");
    cmd->add_flag("--dress", args->dress,
                  "Also work out the least fret material to take off, fret by fret, so that every note passes at the "
                  "last attack of --strength and this set-up (dress.csv, dress_map.csv: the map after)");
    cmd->add_option("--dress-depth", args->dress_depth, "The fret dress: at most this much off any fret (default 0.3 mm)");
    cmd->add_option("--crown", args->crown,
                    "The fret dress: the crowns kept at least this high above the board (default 0.75 mm)");
    cmd->add_option("--fall-away", args->fall_away,
                    "The fret dress: first a fall-away over the frets past this one (dressed down along a line to the "
                    "last fret)");
    cmd->add_option("--jobs", args->jobs, "Threads (default: every core)");
    cmd->add_option("--ensemble", args->ensemble,
                    "The most plucks per note (default: the instrument's, 40; each note stops once its verdict is sure)");
    cmd->add_flag("--stiffness-check", args->stiffness_check,
                  "Also replay every note with each string's bending stiffness x 0.5 and x 1.5 (stiffness_sensitive)");
    cmd->add_flag("--no-clean-up-to", args->no_clean_up_to, "Skip the search of how hard each note can be played");
    cmd->add_option("--partial-scatter", args->partial_scatter,
                    "Detune each stopped note's partials at random by this rms, in cents (default 0: the model's own)");
    cmd->add_option("--listen", args->listen,
                    "What the bench hears: rig (the pickup's circuit and a cabinet, default) or pickup (its full range)");
    cmd->add_option("--fs", args->fs, "Sampling rate (default: the instrument's)");
    cmd->add_option("--duration", args->duration, "Seconds per note (default: the instrument's)");
    cmd->add_flag("--quiet", args->quiet, "No progress lines");
    cmd->callback([args, &action] { action = [args] { return setup_command(*args); }; });
}

}  // namespace fretbuzz::cli
