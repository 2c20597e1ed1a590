// `fretbuzz cases` lists the built-in cases; `fretbuzz show CASE` prints one's file.
#include <iostream>
#include <memory>

#include "../Commands.hpp"
#include "fretbuzz/io/CaseFile.hpp"

namespace fretbuzz::cli {

void add_cases_commands(CLI::App& app, Action& action) {
    CLI::App* cases = app.add_subcommand("cases", "List the built-in cases, one per line");
    cases->callback([&action] {
        action = [] {
            for (const auto& info : builtin_cases()) std::cout << info.name << "\t" << info.description << "\n";
            return 0;
        };
    });
    auto name = std::make_shared<std::string>();
    CLI::App* show = app.add_subcommand("show", "Print a built-in case file, to copy and edit");
    show->add_option("case", *name, "Built-in case name")->required();
    show->callback([name, &action] {
        action = [name] {
            std::cout << builtin_case_text(*name);
            return 0;
        };
    });
}

}  // namespace fretbuzz::cli
