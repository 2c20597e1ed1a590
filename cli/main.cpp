// The fretbuzz command: a thin layer that parses arguments and calls the library.
// Errors in the user's input exit with status 2, numerical failures with 3.
#include <iostream>
#include <string>

#include "Commands.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/Version.hpp"

namespace fretbuzz::cli {
namespace {
std::string invocation;
}
const std::string& command_line() { return invocation; }
}  // namespace fretbuzz::cli

int main(int argc, char** argv) {
    using namespace fretbuzz;
    for (int k = 0; k < argc; ++k) cli::invocation.append(k > 0 ? " " : "").append(argv[k]);
    CLI::App app{"fretbuzz: strings vibrating against obstacles (modal scheme, exact energy balance)"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "fretbuzz " + std::string(version));
    cli::Action action;
    cli::add_run_command(app, action);
    cli::add_cases_commands(app, action);
    cli::add_convergence_command(app, action);
    cli::add_cross_check_command(app, action);
    cli::add_modes_command(app, action);
    cli::add_plot_command(app, action);
    cli::add_report_command(app, action);
    cli::add_sweep_command(app, action);
    cli::add_setup_command(app, action);
    cli::add_estimate_command(app, action);
    cli::add_play_command(app, action);

    CLI11_PARSE(app, argc, argv);
    try {
        return action ? action() : 0;
    } catch (const InputError& e) {
        std::cerr << "fretbuzz: error: " << e.what() << "\n";
        return 2;
    } catch (const SolverError& e) {
        std::cerr << "fretbuzz: solver error: " << e.what() << "\n";
        return 3;
    } catch (const std::exception& e) {
        std::cerr << "fretbuzz: failed: " << e.what() << "\n";
        return 1;
    }
}
