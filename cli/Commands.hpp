#pragma once
// Each subcommand of `fretbuzz` lives in its own file under cli/commands/ and registers
// itself on the application; the command runs through the returned callback.
#include <CLI/CLI.hpp>
#include <functional>

namespace fretbuzz::cli {

using Action = std::function<int()>;

// Each adds its subcommand to app and sets `action` to run when it is chosen.
void add_run_command(CLI::App& app, Action& action);
void add_cases_commands(CLI::App& app, Action& action);  // cases, show

}  // namespace fretbuzz::cli
