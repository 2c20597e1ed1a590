#pragma once
// One output file written all or nothing. The writer writes a temporary file beside the
// target (in the same folder, so on the same file system); commit() flushes it to disk (fsync),
// renames it over the target and syncs the folder, so that after a crash the folder holds the
// old file or the new one, whole. Until commit() the target is untouched: a full disk, an
// error or an interrupt leaves an earlier file as it was, and the temporary file is removed.
// The target is checked when the AtomicFile is made, before any work: a missing folder, a
// folder or a special file (FIFO, socket, device) in the target's place, or a name too long
// is an InputError. A symbolic link in the target's place is replaced by the new file; the
// file it pointed to is left alone. An existing target's permission bits are kept.
#include <filesystem>
#include <string>

namespace fretbuzz {

class AtomicFile {
public:
    // `what` starts every message (say "--out"). Creates the temporary file, empty, under a
    // name of its own (".<name>.tmp-<pid>-<n><extension>", the extension in lower case, as
    // writers choose the format from it).
    AtomicFile(const std::filesystem::path& target, const std::string& what);
    ~AtomicFile();  // removes the temporary file unless commit() ran
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;

    // Where the writer writes.
    const std::filesystem::path& temporary() const { return temporary_; }
    const std::filesystem::path& target() const { return target_; }
    // Flushes the temporary file, renames it to the target and syncs the folder;
    // std::runtime_error naming the file and the system's reason if any step fails (the
    // target is then as it was).
    void commit();

private:
    std::filesystem::path target_;
    std::filesystem::path temporary_;
    bool committed_ = false;
};

}  // namespace fretbuzz
