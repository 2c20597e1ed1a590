// `fretbuzz report DIR`: the plots, then one self-contained report.html (figures, audio
// players, summary and case file) in the run's output directory.
#include <iostream>
#include <memory>
#include <string>

#include "../Commands.hpp"
#include "fretbuzz/io/HtmlReport.hpp"

namespace fretbuzz::cli {

namespace {


int report_command(const FigureArguments& a) {
    make_plots(a.dir, a.animation, a.quiet);
    const std::filesystem::path page = write_html_report(a.dir);
    if (!a.quiet) std::cerr << "fretbuzz: report: " << page.string() << "\n";
    return 0;
}

}  // namespace

int make_report(const std::filesystem::path& dir, bool quiet) {
    return report_command({.dir = dir.string(), .animation = "gif", .quiet = quiet});
}

void add_report_command(CLI::App& app, Action& action) {
    auto args = std::make_shared<FigureArguments>();
    CLI::App* cmd = app.add_subcommand("report", "Plots and a self-contained report.html for a run's output directory");
    add_figure_options(*cmd, *args);
    cmd->callback([args, &action] { action = [args] { return report_command(*args); }; });
}

}  // namespace fretbuzz::cli
