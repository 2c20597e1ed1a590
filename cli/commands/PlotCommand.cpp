// `fretbuzz plot DIR`: figures (PNG, PDF or SVG) of a run (signal with zooms and energy, spectrogram,
// energy balance, contactogram, string snapshots) and, when the run stored snapshots, an
// animation of the string over the obstacle; of a run of strings on a bridge, each string's
// energy and the bridge's over time. The drawing is done by the embedded Python
// script; this command checks the input and runs it.
#include <memory>
#include <stdexcept>
#include <string>

#include "../Commands.hpp"
#include "../PythonScript.hpp"
#include "fretbuzz/Error.hpp"

namespace fretbuzz::cli {

namespace fs = std::filesystem;

namespace {

void require_results(const fs::path& dir) {
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        throw InputError("DIR " + dir.string() + ": no such directory (give the --out directory of `fretbuzz run`)");
    // A sweep's folder holds a results.h5 too, of another layout: its table.
    if (fs::is_regular_file(dir / "sweep.toml", ec))
        throw InputError("DIR " + dir.string() +
                         ": holds a sweep (sweep.toml, the table in results.csv and results.h5), not a run's "
                         "results: plot one run of it (`fretbuzz run` its case with the run's values, --out DIR), "
                         "or read the table in Python with fretbuzz.read_table(\"" + dir.string() + "\")");
    // A run of strings on a bridge: its strings.csv (the energy passing between the strings).
    if (!fs::is_regular_file(dir / "results.h5", ec) && fs::is_regular_file(dir / "strings.csv", ec)) return;
    if (!fs::is_regular_file(dir / "results.h5", ec))
        throw InputError("DIR " + dir.string() + ": holds no results.h5 (write one with `fretbuzz run CASE --out " +
                         dir.string() + "`)");
}


}  // namespace

// "START:END" in s, START < END, both >= 0.
void check_zoom(const std::string& window) {
    const std::size_t colon = window.find(':');
    try {
        std::size_t used_a = 0, used_b = 0;
        const std::string a = window.substr(0, colon), b = colon == std::string::npos ? "" : window.substr(colon + 1);
        const double start = std::stod(a, &used_a), end = std::stod(b, &used_b);
        if (used_a == a.size() && used_b == b.size() && start >= 0.0 && end > start) return;
    } catch (const std::exception&) {
    }
    throw InputError("--zoom " + window + ": must be START:END in s with 0 <= START < END (e.g. 0.01:0.03)");
}

void make_plots(const FigureArguments& a) {
    require_results(a.dir);
    if (a.animation != "gif" && a.animation != "mp4" && a.animation != "none")
        throw InputError("--animation " + a.animation + ": must be gif, mp4 or none");
    std::vector<std::string> arguments{a.dir, "--animation", a.animation};
    if (a.quiet) arguments.emplace_back("--quiet");
    for (const std::string& f : a.formats) {
        if (f != "png" && f != "pdf" && f != "svg") throw InputError("--format " + f + ": must be png, pdf or svg");
        arguments.insert(arguments.end(), {"--format", f});
    }
    for (const std::string& z : a.zooms) {
        check_zoom(z);
        arguments.insert(arguments.end(), {"--zoom", z});
    }
    if (a.db_range) {
        if (!(*a.db_range > 0.0 && *a.db_range <= 300.0))
            throw InputError(out_of_range_message("--db-range (dB)", *a.db_range, "must be in (0, 300]"));
        arguments.insert(arguments.end(), {"--db-range", std::to_string(*a.db_range)});
    }
    if (a.max_frequency) {
        require_positive("--max-frequency (Hz)", *a.max_frequency);
        arguments.insert(arguments.end(), {"--max-frequency", std::to_string(*a.max_frequency)});
    }
    const int status = run_python_script(plot_script(), arguments);
    if (status != 0) throw std::runtime_error("the plotting script failed (exit status " + std::to_string(status) + ")");
}

void add_figure_options(CLI::App& command, FigureArguments& args) {
    command.add_option("DIR", args.dir, "Output directory of `fretbuzz run` (holding results.h5)")->required();
    command.add_option("--animation", args.animation, "Animation format when snapshots exist: gif, mp4 (ffmpeg) or none")
        ->capture_default_str();
    command.add_flag("-q,--quiet", args.quiet, "Do not list the files written");
    command.add_option("--format", args.formats, "Figure file format: png, pdf or svg (repeatable; default png)");
    command.add_option("--zoom", args.zooms, "A zoomed window START:END in s of signal.png (repeatable; default: "
                                             "the first contacts, the middle, the end)");
    command.add_option("--db-range", args.db_range, "Spectrogram colour range below its peak in dB (default 60)");
    command.add_option("--max-frequency", args.max_frequency, "Spectrogram's top frequency in Hz (default 10000)");
}

void add_plot_command(CLI::App& app, Action& action) {
    auto args = std::make_shared<FigureArguments>();
    CLI::App* cmd = app.add_subcommand("plot", "Draw plots (PNG, PDF, SVG) and an animation of a run's output directory");
    add_figure_options(*cmd, *args);
    cmd->callback([args, &action] {
        action = [args] {
            make_plots(*args);
            return 0;
        };
    });
}

}  // namespace fretbuzz::cli
