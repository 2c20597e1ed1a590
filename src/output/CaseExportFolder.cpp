#include "fretbuzz/output/CaseExportFolder.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <set>
#include <string>

#include "../FileDescriptor.hpp"
#include "IoFailure.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/CaseExport.hpp"
#include "fretbuzz/output/OutputDirectory.hpp"

namespace fretbuzz {

namespace fs = std::filesystem;

namespace {

// A new file in the staging folder (never through a link, never over a file), written whole.
void write_new_file(const fs::path& path, std::string_view text) {
    FileDescriptor fd(::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666));
    if (fd.get() < 0) io_failure("create", path, errno);
    if (const int error = write_fully(fd.get(), text.data(), text.size()); error != 0) io_failure("write", path, error);
    if (fd.close() != 0) io_failure("write", path, errno);
}

}  // namespace

std::vector<fs::path> export_builtin_case(std::string_view name, const fs::path& dir) {
    const std::vector<ExportedFile> files = builtin_case_files(name);  // an unknown name: nothing created
    const std::string what = "export DIR";
    // The export adds its files to DIR and replaces none: a name it writes must be free there.
    std::set<std::string> top;
    for (const ExportedFile& f : files) top.insert(fs::path(f.path).begin()->string());
    for (const std::string& t : top) {
        struct stat info {};
        if (::lstat((dir / t).c_str(), &info) == 0)
            throw InputError(what + " " + dir.string() + ": " + (dir / t).string() + " exists (" +
                             (S_ISLNK(info.st_mode)  ? "a symbolic link"
                              : S_ISDIR(info.st_mode) ? "a folder"
                                                      : "a file") +
                             "); an export writes only new files and never replaces or follows one: move it away, or "
                             "give a new or empty folder");
    }
    OutputDirectory out(dir, what);
    std::vector<fs::path> written;
    for (const ExportedFile& f : files) {
        write_new_file(out.staged(f.path), f.text);
        written.push_back(dir / f.path);
    }
    out.commit();
    return written;
}

}  // namespace fretbuzz
