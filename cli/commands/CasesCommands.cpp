// `fretbuzz cases` lists the built-in cases; `fretbuzz show NAME` prints a built-in case's
// or instrument's file (a strings case's with what each string is as read);
// `fretbuzz export CASE DIR` writes it with its data files (a strings case with its strings' cases).
#include <iostream>
#include <memory>
#include <utility>

#include "../Commands.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/output/CaseExportFolder.hpp"
#include "fretbuzz/input/BuiltinFiles.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/StringsCaseFile.hpp"
#include "fretbuzz/input/InstrumentFile.hpp"

namespace fretbuzz::cli {

void add_cases_commands(CLI::App& app, Action& action) {
    CLI::App* cases = app.add_subcommand("cases", "List the built-in cases, one per line");
    cases->callback([&action] {
        action = [] {
            for (const auto& info : builtin_cases()) std::cout << info.name << "\t" << info.description << "\n";
            for (const auto& info : builtin_strings_cases()) std::cout << info.name << "\t" << info.description << "\n";
            return 0;
        };
    });
    auto name = std::make_shared<std::string>();
    auto instrument_only = std::make_shared<bool>(false);
    CLI::App* show = app.add_subcommand("show", "Print a built-in case or instrument file, to copy and edit");
    show->add_option("name", *name, "A built-in case (fretbuzz cases), a strings case file, a file a strings case names "
                    "(bridges/taraf-string.toml) or an instrument (jazz-bass, electric-guitar, ...)")
        ->required();
    show->add_flag("--instrument", *instrument_only, "The instrument of that name (bass-neck is also a case)");
    show->callback([name, instrument_only, &action] {
        action = [name, instrument_only] {
            if (!*instrument_only && is_builtin_case(*name)) {
                std::cout << builtin_case_text(*name);
                return 0;
            }
            // Strings on a bridge (built-in or a file): the case as written, then each string as read.
            if (!*instrument_only)
                if (const auto strings = read_strings_case_text(*name)) {
                    std::cout << strings->text << describe_strings_case(parse_strings_case(*strings));
                    return 0;
                }
            // A one-string case a strings case names by its built-in path (bridges/taraf-string.toml).
            if (const auto file = find_builtin_file(*name); file && !*instrument_only && name->ends_with(".toml")) {
                std::cout << *file;
                return 0;
            }
            if (const auto text = builtin_instrument_text(*name)) {
                std::cout << *text;
                return 0;
            }
            std::string case_names, instruments;
            for (const auto& info : builtin_cases()) case_names += (case_names.empty() ? "" : ", ") + info.name;
            for (const auto& info : builtin_strings_cases()) case_names += ", " + info.name;
            for (const auto& info : builtin_instruments()) instruments += (instruments.empty() ? "" : ", ") + info.name;
            throw InputError("show " + *name + ": no built-in " + (*instrument_only ? "instrument" : "case or instrument") +
                             " of that name (cases: " + case_names + "; instruments: " + instruments + ")");
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
