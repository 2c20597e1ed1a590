// `fretbuzz cases` lists the built-in cases; `fretbuzz show CASE` prints one's file;
// `fretbuzz export CASE DIR` writes it with its data files.
#include <iostream>
#include <memory>
#include <utility>

#include "../Commands.hpp"
#include "fretbuzz/input/CaseExport.hpp"

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
    auto exported = std::make_shared<std::pair<std::string, std::string>>();
    CLI::App* exp = app.add_subcommand("export", "Write a built-in case file and its data files to DIR, to edit and run");
    exp->add_option("case", exported->first, "Built-in case name")->required();
    exp->add_option("dir", exported->second, "Folder to write into (created)")->required();
    exp->callback([exported, &action] {
        action = [exported] {
            for (const auto& path : export_builtin_case(exported->first, exported->second)) std::cout << path.string() << "\n";
            return 0;
        };
    });
}

}  // namespace fretbuzz::cli
