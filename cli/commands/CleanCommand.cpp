// `fretbuzz clean DIR`: removes the staging folders that runs into DIR left behind when
// they were killed outright (SIGKILL, power loss). A run in progress keeps its own.
#include <iostream>
#include <memory>

#include "../Commands.hpp"
#include "fretbuzz/output/OutputDirectory.hpp"

namespace fretbuzz::cli {

void add_clean_command(CLI::App& app, Action& action) {
    auto dir = std::make_shared<std::string>();
    CLI::App* cmd = app.add_subcommand("clean", "Remove staging folders left by killed runs into DIR (and folders in DIR)");
    cmd->add_option("dir", *dir, "An output directory (--out of a run)")->required();
    cmd->callback([dir, &action] {
        action = [dir] {
            const std::size_t removed = remove_stale_staging(*dir);
            std::cerr << "fretbuzz: removed " << removed << " stale staging folder" << (removed == 1 ? "" : "s") << "\n";
            return 0;
        };
    });
}

}  // namespace fretbuzz::cli
