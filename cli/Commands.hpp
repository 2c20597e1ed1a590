#pragma once
// Each subcommand of `fretbuzz` lives in its own file under cli/commands/ and registers
// itself on the application; the command runs through the returned callback.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace fretbuzz::cli {

using Action = std::function<int()>;

// The command line as typed (the arguments joined by spaces): the outputs record it.
const std::string& command_line();

// Each adds its subcommand to app and sets `action` to run when it is chosen.
void add_run_command(CLI::App& app, Action& action);
void add_cases_commands(CLI::App& app, Action& action);  // cases, show
void add_convergence_command(CLI::App& app, Action& action);
void add_cross_check_command(CLI::App& app, Action& action);  // modal vs finite differences
void add_modes_command(CLI::App& app, Action& action);
void add_plot_command(CLI::App& app, Action& action);
void add_report_command(CLI::App& app, Action& action);
void add_sweep_command(CLI::App& app, Action& action);  // parameter sweeps, local or Dask
void add_setup_command(CLI::App& app, Action& action);  // neck set-up study, buzz map
void add_studio_command(CLI::App& app, Action& action);  // the set-up bench in a browser
void add_estimate_command(CLI::App& app, Action& action);  // recording -> mode table
void add_play_command(CLI::App& app, Action& action);  // performance through the real-time engine
void add_clean_command(CLI::App& app, Action& action);  // stale staging folders of killed runs

// SIGINT and SIGTERM ask the running simulation to stop at its next step boundary (it then
// discards its staging folder and the command exits 130 or 143) instead of killing it.
void stop_cleanly_on_signals();

// What `plot` and `report` take: a run's output directory and how to draw it.
struct FigureArguments {
    std::string dir;
    std::string animation = "gif";
    bool quiet = false;
    std::vector<std::string> formats;  // png, pdf, svg (default png)
    std::vector<std::string> zooms;    // START:END in s, the zoomed windows of signal.png
    std::optional<double> db_range;    // of the spectrogram, below its peak
    std::optional<double> max_frequency;  // of the spectrogram, Hz
};
void add_figure_options(CLI::App& command, FigureArguments& args);

// The plots (and the animation: "gif", "mp4" or "none") of a run's output directory;
// throws InputError naming DIR if it holds no results.h5, or naming a bad option.
void make_plots(const FigureArguments& args);
// The plots, then report.html; returns the exit status.
int make_report(const std::filesystem::path& dir, bool quiet);

}  // namespace fretbuzz::cli
