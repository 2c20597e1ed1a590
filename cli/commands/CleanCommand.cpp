// `fretbuzz clean DIR`: removes what killed or failed commands left in DIR: the staging
// folders of runs killed outright (SIGKILL, power loss), and in a sweep's folder the
// half-written temporary files of a sweep stopped by a full disk or a kill. A run or a
// sweep in progress keeps its own. In a studio's study folder, the maps a killed studio left
// unfinished, and with --keep-maps N all but the newest N maps (the studio's package does
// that: the study folder is its own, and it refuses while a studio works in it).
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "../Commands.hpp"
#include "../PythonScript.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/output/OutputDirectory.hpp"
#include "fretbuzz/sweep/SweepStore.hpp"

namespace fretbuzz::cli {

namespace {

const char* plural(std::size_t n) { return n == 1 ? "" : "s"; }

// The file a studio keeps in its study folder (its lock: python/fretbuzz/studio/study.py).
constexpr const char* kStudyMark = ".fretbuzz-studio.lock";

}  // namespace

void add_clean_command(CLI::App& app, Action& action) {
    auto dir = std::make_shared<std::string>();
    auto keep_maps = std::make_shared<std::string>();
    CLI::App* cmd = app.add_subcommand(
        "clean", "Remove staging folders left by killed runs into DIR (and folders in DIR), a stopped sweep's "
                 "temporary files, or a study folder's unfinished (and, on request, old) maps");
    cmd->add_option("dir", *dir, "An output directory (--out of a run or of a sweep) or a studio's study folder")
        ->required();
    cmd->add_option("--keep-maps", *keep_maps, "In a study folder: remove all but the newest N finished maps");
    cmd->callback([dir, keep_maps, &action] {
        action = [dir, keep_maps] {
            std::error_code ec;
            // A missing DIR may still have the staging folder of a killed first run into it
            // beside it; with none, a mistyped folder is said so, not passed as a success.
            const std::filesystem::file_status status = std::filesystem::status(*dir, ec);
            if (!std::filesystem::exists(status)) {
                const std::size_t removed = keep_maps->empty() ? remove_stale_staging(*dir) : 0;
                if (removed == 0)
                    throw InputError("clean " + *dir + ": no such folder, and no staging folder of a run into it "
                                     "(give an output directory, a sweep's folder or a study folder)");
                std::cerr << "fretbuzz: removed " << removed << " stale staging folder" << plural(removed) << "\n";
                return 0;
            }
            if (!std::filesystem::is_directory(status)) throw InputError("clean " + *dir + ": is not a folder");
            if (std::filesystem::is_regular_file(std::filesystem::path(*dir) / kStudyMark, ec)) {
                std::vector<std::string> words{*dir};
                if (!keep_maps->empty()) words.insert(words.end(), {"--keep-maps", *keep_maps});
                return run_package_main("studio.clean", words);
            }
            if (!keep_maps->empty())
                throw InputError("--keep-maps: " + *dir + " is not a study folder (no " + std::string(kStudyMark) + ")");
            const std::size_t removed = remove_stale_staging(*dir);
            std::cerr << "fretbuzz: removed " << removed << " stale staging folder" << plural(removed) << "\n";
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
