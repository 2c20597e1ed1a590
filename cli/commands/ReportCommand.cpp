// `fretbuzz report DIR`: the plots, then one self-contained report.html (figures, audio
// players, summary and case file) in the run's output directory.
#include <algorithm>
#include <iostream>
#include <memory>
#include <string>

#include "../Commands.hpp"
#include "fretbuzz/output/HtmlReport.hpp"

namespace fretbuzz::cli {

namespace {


int report_command(FigureArguments a) {
    // The page embeds the PNGs: draw them whatever other formats are asked for.
    if (!a.formats.empty() && std::find(a.formats.begin(), a.formats.end(), "png") == a.formats.end())
        a.formats.emplace_back("png");
    make_plots(a);
    const std::filesystem::path page = write_html_report(a.dir);
    if (!a.quiet) std::cerr << "fretbuzz: report: " << page.string() << "\n";
    return 0;
}

}  // namespace

int make_report(const std::filesystem::path& dir, bool quiet) {
    FigureArguments a;
    a.dir = dir.string();
    a.quiet = quiet;
    return report_command(a);
}

void add_report_command(CLI::App& app, Action& action) {
    auto args = std::make_shared<FigureArguments>();
    CLI::App* cmd = app.add_subcommand("report", "Plots and a self-contained report.html for a run's output directory");
    add_figure_options(*cmd, *args);
    cmd->callback([args, &action] { action = [args] { return report_command(*args); }; });
}

}  // namespace fretbuzz::cli
