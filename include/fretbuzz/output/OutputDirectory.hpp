#pragma once
// All-or-nothing output. Files are written into a staging folder beside the output
// directory (same parent, so same file system); commit() syncs them to disk and then swaps
// the staging folder and the directory in one rename (renameat2 RENAME_EXCHANGE), so a
// reader sees either the old set or the new one, never a mix. The new set replaces the
// old one whole: files of an older run that this run does not write (say audio_0.5m.wav)
// are gone; files fretbuzz never writes (a user's notes) are kept, hard-linked into the
// new set. A run that fails or is interrupted leaves nothing behind: no staging folder,
// and no directory (or parents) it created. Staging folders of a run that was killed
// (SIGKILL, power loss) are found by their lock and removed by the next run into the same
// directory, or by remove_stale_staging() (`fretbuzz clean DIR`).
#include <sys/types.h>

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace fretbuzz {

class OutputDirectory {
public:
    // Checks dir (InputError naming `what`, the option or argument that gave it: a file in the
    // way, a name too long, a folder that fretbuzz did not write inside it, not writable) and
    // creates the staging folder and any missing parents of dir.
    explicit OutputDirectory(const std::filesystem::path& dir, const std::string& what = "--out");
    ~OutputDirectory();  // discards the staged files unless commit() ran
    OutputDirectory(const OutputDirectory&) = delete;
    OutputDirectory& operator=(const OutputDirectory&) = delete;

    // Where a writer should write `name` (inside the staging folder); a name with folders
    // ("bridges/taraf-string.toml") gets them created there.
    std::filesystem::path staged(const std::string& name);
    // Makes the staged files the directory's content at once. Throws (runtime_error naming
    // the file, or Interrupted before the swap) and leaves the old content intact on failure.
    void commit();
    const std::filesystem::path& path() const { return dir_; }

    // The file system's limits where the directory is: bytes in one name, and in a path (its
    // terminating zero excluded).
    struct NameLimits {
        std::size_t name = 0, path = 0;
    };

private:
    void discard() noexcept;
    void keep_owner(const std::string& given);

    struct Kept {  // of an existing directory: what the one that replaces it keeps
        mode_t mode;
        uid_t uid;
        gid_t gid;
    };

    std::filesystem::path dir_;      // as given
    std::string label_;              // what gave it, and the name as given: starts every message
    std::filesystem::path target_;   // absolute, symbolic links followed: what gets swapped
    std::filesystem::path staging_;  // sibling of target_
    std::filesystem::path widest_staging_;  // as long as any run's staging folder: what names are checked in
    std::filesystem::path lock_;     // held while this run lives: a staging folder without a held lock is stale
    int lock_fd_ = -1;
    std::vector<std::string> names_;
    std::vector<std::filesystem::path> created_;  // parents this run created, outermost first
    std::optional<Kept> kept_;
    NameLimits limits_{};
    bool committed_ = false;
};

// Removes the staging folders that runs into `dir` left when they were killed (their lock is
// free), and those of runs into folders inside `dir`. Returns how many it removed.
std::size_t remove_stale_staging(const std::filesystem::path& dir);

// True for the names of files a run or its report writes (observation.csv, audio*.wav,
// report.html, ...): files of an older run with these names are replaced or removed.
bool is_run_output_name(const std::string& name);

}  // namespace fretbuzz
