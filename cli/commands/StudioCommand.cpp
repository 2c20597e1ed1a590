// `fretbuzz studio [INSTRUMENT] [--port N] [--host H]`: the set-up bench in a browser. The page
// is served by the Python package (fretbuzz.studio: FastAPI, uvicorn, Jinja2) over the same
// library as `fretbuzz setup`; this file only hands the options over. The options' checks are
// the package's (an instrument or a value out of range: exit 2, a port in use: exit 1).
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "../Commands.hpp"
#include "../PythonScript.hpp"

namespace fretbuzz::cli {

namespace {

struct StudioArguments {
    std::string instrument, port, host, study, strength, ensemble, fs, duration, jobs, keep_maps;
    std::vector<std::string> allow_hosts;
    bool finger = false;
};

int studio_command(const StudioArguments& a) {
    stop_cleanly_on_signals();  // Ctrl-C reaches the server too: it stops, and this returns its status
    std::vector<std::string> words;
    if (!a.instrument.empty()) words.push_back(a.instrument);
    const std::pair<const char*, const std::string*> options[] = {
        {"--port", &a.port},         {"--host", &a.host}, {"--study", &a.study},       {"--strength", &a.strength},
        {"--ensemble", &a.ensemble}, {"--fs", &a.fs},     {"--duration", &a.duration}, {"--jobs", &a.jobs},
        {"--keep-maps", &a.keep_maps}};
    for (const auto& [option, value] : options)
        if (!value->empty()) {
            words.push_back(option);
            words.push_back(*value);
        }
    for (const std::string& name : a.allow_hosts) {
        words.push_back("--allow-host");
        words.push_back(name);
    }
    if (a.finger) words.push_back("--finger");
    return run_package_main("studio", words);
}

}  // namespace

void add_studio_command(CLI::App& app, Action& action) {
    auto args = std::make_shared<StudioArguments>();
    CLI::App* cmd = app.add_subcommand(
        "studio", "Set-up bench in a browser: the buzz map, what-ifs, each note's sound and contacts, advice, a report");
    cmd->add_option("instrument", args->instrument,
                    "A built-in instrument (jazz-bass, the default; electric-guitar, bass-5, bass-neck) or an instrument file");
    cmd->add_option("--port", args->port, "Port on 127.0.0.1 (default 8035; 0: any free port)");
    cmd->add_option("--host", args->host,
                    "Serve other computers on this address (e.g. 0.0.0.0), behind a token printed in the address; "
                    "without it only this computer may connect");
    cmd->add_option("--allow-host", args->allow_hosts,
                    "With --host: a name other computers use for this one in their browser's address (repeatable)")
        ->allow_extra_args(false);
    cmd->add_option("--keep-maps", args->keep_maps,
                    "Remove all but the newest N finished maps of the study folder before starting");
    cmd->add_option("--study", args->study, "Study folder: the notes' sounds and the reports (default: studio-INSTRUMENT)");
    cmd->add_option("--strength", args->strength, "Attacks of the first map (default: medium; soft, hard, pop, slap, or mm)");
    cmd->add_option("--ensemble", args->ensemble, "The most plucks per note (default: the instrument's, 40)");
    cmd->add_option("--fs", args->fs, "Sampling rate in Hz (default: the instrument's)");
    cmd->add_option("--duration", args->duration, "Seconds per note (default: the instrument's)");
    cmd->add_option("--jobs", args->jobs, "Threads (default: every core)");
    cmd->add_flag("--finger", args->finger, "Stopped notes by the finger model (slow) instead of the stand-in");
    cmd->callback([args, &action] { action = [args] { return studio_command(*args); }; });
}

}  // namespace fretbuzz::cli
