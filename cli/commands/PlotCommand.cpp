// `fretbuzz plot DIR`: PNG figures of a run (signal with zooms and energy, spectrogram,
// energy balance, contactogram, string snapshots) and, when the run stored snapshots, an
// animation of the string over the obstacle. The drawing is done by the embedded Python
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
    if (!fs::is_regular_file(dir / "results.h5", ec))
        throw InputError("DIR " + dir.string() + ": holds no results.h5 (write one with `fretbuzz run CASE --out " +
                         dir.string() + "`)");
}


}  // namespace

void make_plots(const fs::path& dir, const std::string& animation, bool quiet) {
    require_results(dir);
    if (animation != "gif" && animation != "mp4" && animation != "none")
        throw InputError("--animation " + animation + ": must be gif, mp4 or none");
    std::vector<std::string> arguments{dir.string(), "--animation", animation};
    if (quiet) arguments.emplace_back("--quiet");
    const int status = run_python_script(plot_script(), arguments);
    if (status != 0) throw std::runtime_error("the plotting script failed (exit status " + std::to_string(status) + ")");
}

void add_figure_options(CLI::App& command, FigureArguments& args) {
    command.add_option("DIR", args.dir, "Output directory of `fretbuzz run` (holding results.h5)")->required();
    command.add_option("--animation", args.animation, "Animation format when snapshots exist: gif, mp4 (ffmpeg) or none")
        ->capture_default_str();
    command.add_flag("-q,--quiet", args.quiet, "Do not list the files written");
}

void add_plot_command(CLI::App& app, Action& action) {
    auto args = std::make_shared<FigureArguments>();
    CLI::App* cmd = app.add_subcommand("plot", "Draw PNG plots (and an animation) of a run's output directory");
    add_figure_options(*cmd, *args);
    cmd->callback([args, &action] {
        action = [args] {
            make_plots(args->dir, args->animation, args->quiet);
            return 0;
        };
    });
}

}  // namespace fretbuzz::cli
