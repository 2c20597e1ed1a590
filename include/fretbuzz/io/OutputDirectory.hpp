#pragma once
// All-or-nothing output: files are written into a hidden staging folder inside the
// output directory and moved into place only when the run succeeds. A failed run leaves
// nothing behind (not even the directory, if the run created it).
#include <filesystem>
#include <string>
#include <vector>

namespace fretbuzz {

class OutputDirectory {
public:
    // Creates (if needed) dir and a staging folder in it; throws InputError naming --out
    // if either cannot be created or written.
    explicit OutputDirectory(const std::filesystem::path& dir);
    ~OutputDirectory();  // discards the staged files unless commit() ran
    OutputDirectory(const OutputDirectory&) = delete;
    OutputDirectory& operator=(const OutputDirectory&) = delete;

    // Where a writer should write `name` (inside the staging folder).
    std::filesystem::path staged(const std::string& name);
    // Moves every staged file into the directory, replacing older files of the same name.
    void commit();
    const std::filesystem::path& path() const { return dir_; }

private:
    std::filesystem::path dir_;
    std::filesystem::path staging_;
    std::vector<std::string> names_;
    bool created_dir_ = false;
    bool committed_ = false;
};

}  // namespace fretbuzz
