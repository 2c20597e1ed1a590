// `fretbuzz setup CASE --out DIR`: the neck set-up study. Plays every fret of the case's
// string as one sweep and draws the buzz map; the study itself lives in the Python package
// (fretbuzz.neck, fretbuzz.buzzmap) over the same library, this command only hands over.
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "../Commands.hpp"
#include "../PythonScript.hpp"

namespace fretbuzz::cli {

void add_setup_command(CLI::App& app, Action& action) {
    struct Arguments {
        std::string case_name, out;
        std::vector<std::string> raised;
        bool resume = false, quiet = false, finger = false;
    };
    auto args = std::make_shared<Arguments>();
    CLI::App* cmd = app.add_subcommand(
        "setup", "Neck set-up study: play every fret of a string, write buzz_map.html and buzz_map.csv");
    cmd->add_option("case", args->case_name, "A case with a fretboard obstacle and modelled modes (built-in: bass-neck, guitar-neck)")
        ->required();
    cmd->add_option("--out", args->out, "Output directory (the sweep in sweep/, the map in buzz_map.html)")->required();
    const std::vector<std::pair<std::string, std::string>> passed = {
        {"--frets", "Frets to play, e.g. 0-19 or 0,5,7 (default: the open string to the second-last fret)"},
        {"--strength", "Pluck amplitudes in m, e.g. 1e-3,2e-3 (default: the case's)"},
        {"--relief", "Neck relief: bow depth at mid-span in m (default: the case's)"},
        {"--action-nut", "Action at the nut in m"},
        {"--action-last-fret", "Action at the last fret in m"},
        {"--fs", "Sampling rate in Hz (default: the case's)"},
        {"--duration", "Seconds per note (default: the case's)"},
        {"--compare", "An earlier study's --out: both maps side by side, the notes that changed marked"},
        {"--jobs", "Notes at a time on this machine (default: every core)"},
        {"--scheduler", "Run on a Dask cluster: tcp://HOST:PORT"}};
    auto values = std::make_shared<std::vector<std::string>>(passed.size());
    for (std::size_t k = 0; k < passed.size(); ++k) cmd->add_option(passed[k].first, (*values)[k], passed[k].second);
    cmd->add_option("--raise", args->raised, "Raise one fret's top: FRET:METRES, e.g. 7:0.05e-3 (repeatable)");
    cmd->add_flag("--finger", args->finger,
                  "Fretted notes: a finger presses the string behind each fret (slower; default: the string clamped "
                  "on the fret's top)");
    cmd->add_flag("--resume", args->resume, "Finish an interrupted study in --out");
    cmd->add_flag("--quiet", args->quiet, "No progress lines");
    cmd->callback([args, values, passed, &action] {
        action = [args, values, passed] {
            std::vector<std::string> words{args->case_name, "--out", args->out};
            for (std::size_t k = 0; k < passed.size(); ++k)
                if (!(*values)[k].empty()) words.insert(words.end(), {passed[k].first, (*values)[k]});
            for (const std::string& r : args->raised) words.insert(words.end(), {"--raise", r});
            if (args->finger) words.push_back("--finger");
            if (args->resume) words.push_back("--resume");
            if (args->quiet) words.push_back("--quiet");
            return run_package_main("neck", words);
        };
    });
}

}  // namespace fretbuzz::cli
