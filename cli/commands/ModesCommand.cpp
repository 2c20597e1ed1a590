// `fretbuzz modes CASE|FILE`: the mode table a case resolves to, as CSV, so users can see
// which frequencies and dampings were measured and which come from the models.
#include <cstdio>
#include <memory>
#include <string>

#include "../Commands.hpp"
#include "fretbuzz/input/CaseFile.hpp"

namespace fretbuzz::cli {

namespace {

int print_modes(const std::string& case_name) {
    const Case c = load_case(case_name);
    std::printf("mode,frequency_hz,sigma_per_s,source\n");
    for (std::size_t j = 0; j < c.mode_count(); ++j)
        std::printf("%zu,%.17g,%.17g,%s\n", j + 1, c.modes.frequency_hz[j], c.modes.sigma_per_s[j],
                    to_string(c.modes.source[j]).c_str());
    return 0;
}

}  // namespace

void add_modes_command(CLI::App& app, Action& action) {
    auto name = std::make_shared<std::string>();
    CLI::App* cmd = app.add_subcommand("modes", "Print a case's mode table (CSV: mode, frequency, damping, source)");
    cmd->add_option("case", *name, "Built-in case name or path to a .toml file")->required();
    cmd->callback([name, &action] { action = [name] { return print_modes(*name); }; });
}

}  // namespace fretbuzz::cli
