#include "fretbuzz/io/OutputDirectory.hpp"

#include <unistd.h>

#include <fstream>

#include "fretbuzz/Error.hpp"

namespace fretbuzz {

namespace fs = std::filesystem;

OutputDirectory::OutputDirectory(const fs::path& dir) : dir_(dir) {
    std::error_code ec;
    if (!fs::exists(dir_, ec)) {
        fs::create_directories(dir_, ec);
        if (ec) throw InputError("--out " + dir_.string() + ": cannot create the output directory (" + ec.message() + ")");
        created_dir_ = true;
    } else if (!fs::is_directory(dir_, ec)) {
        throw InputError("--out " + dir_.string() + ": exists and is not a directory");
    }
    staging_ = dir_ / (".fretbuzz-partial-" + std::to_string(::getpid()));
    fs::create_directory(staging_, ec);
    const fs::path probe = staging_ / ".probe";
    std::ofstream test(probe);
    if (ec || !test) {
        fs::remove_all(staging_, ec);
        if (created_dir_) fs::remove(dir_, ec);
        throw InputError("--out " + dir_.string() + ": the output directory is not writable");
    }
    test.close();
    fs::remove(probe, ec);
}

OutputDirectory::~OutputDirectory() {
    if (committed_) return;
    std::error_code ec;
    fs::remove_all(staging_, ec);
    if (created_dir_) fs::remove(dir_, ec);  // only removes it if empty
}

fs::path OutputDirectory::staged(const std::string& name) {
    names_.push_back(name);
    return staging_ / name;
}

void OutputDirectory::commit() {
    for (const std::string& name : names_) {
        if (fs::exists(staging_ / name)) fs::rename(staging_ / name, dir_ / name);
    }
    std::error_code ec;
    fs::remove_all(staging_, ec);
    committed_ = true;
}

}  // namespace fretbuzz
