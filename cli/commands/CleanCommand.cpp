// `fretbuzz clean DIR`: removes what killed or failed commands left in DIR: the staging
// folders of runs killed outright (SIGKILL, power loss), and in a sweep's folder the
// half-written temporary files of a sweep stopped by a full disk or a kill. A run or a
// sweep in progress keeps its own.
#include <filesystem>
#include <iostream>
#include <memory>

#include "../Commands.hpp"
#include "fretbuzz/output/OutputDirectory.hpp"
#include "fretbuzz/sweep/SweepStore.hpp"

namespace fretbuzz::cli {

namespace {

const char* plural(std::size_t n) { return n == 1 ? "" : "s"; }

}  // namespace

void add_clean_command(CLI::App& app, Action& action) {
    auto dir = std::make_shared<std::string>();
    CLI::App* cmd = app.add_subcommand(
        "clean", "Remove staging folders left by killed runs into DIR (and folders in DIR), and a stopped sweep's "
                 "temporary files");
    cmd->add_option("dir", *dir, "An output directory (--out of a run or of a sweep)")->required();
    cmd->callback([dir, &action] {
        action = [dir] {
            const std::size_t removed = remove_stale_staging(*dir);
            std::cerr << "fretbuzz: removed " << removed << " stale staging folder" << plural(removed) << "\n";
            std::error_code ec;
            if (std::filesystem::is_regular_file(std::filesystem::path(*dir) / "sweep.toml", ec)) {
                const std::size_t files = SweepStore::remove_stale_files(*dir);
                std::cerr << "fretbuzz: removed " << files << " temporary file" << plural(files)
                          << " of a stopped sweep\n";
            }
            return 0;
        };
    });
}

}  // namespace fretbuzz::cli
