// The output directory as its owner left it: an existing folder keeps its mode, owner and
// group when a run replaces its content; nothing fretbuzz did not write is ever deleted (a
// FIFO, socket or device node in the way stops the run, exit 2, naming it); a symbolic link
// given as --out leads to its folder and stays a link; a path the file system cannot hold
// the run's files under is refused before anything is computed.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sndfile.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

#include "TestSupport.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/output/OutputDirectory.hpp"

namespace fretbuzz {
namespace {

namespace fs = std::filesystem;
using testing::run_cli;
using testing::ScratchDir;

const std::string kShortRun = "run bass-pluck --fs 100000 --duration 0.005 -q --out ";

struct stat stat_of(const fs::path& path) {
    struct stat st {};
    EXPECT_EQ(::lstat(path.c_str(), &st), 0) << path;
    return st;
}

// One file written and committed, as a run's outputs are.
void write_into(const fs::path& dir) {
    OutputDirectory out(dir);
    std::ofstream(out.staged("summary.json")) << "{}\n";
    out.commit();
}

TEST(OutputDirectory, AnExistingFolderKeepsItsModeOwnerAndGroup) {
    ScratchDir scratch("out-mode");
    const fs::path dir = scratch.path() / "mine";
    fs::create_directory(dir);
    // Owned by another user where this process may give it one (as root): a 0700 folder of
    // someone else's must stay theirs and closed.
    const bool root = ::geteuid() == 0;
    const uid_t owner = root ? 65534 : ::geteuid();
    const gid_t group = root ? 65534 : ::getegid();
    ASSERT_EQ(::chown(dir.c_str(), owner, group), 0);
    const mode_t mode = root ? 0700 : 0750;
    ASSERT_EQ(::chmod(dir.c_str(), mode), 0);
    write_into(dir);
    const struct stat after = stat_of(dir);
    EXPECT_TRUE(S_ISDIR(after.st_mode));
    EXPECT_EQ(after.st_mode & 07777, mode) << std::oct << (after.st_mode & 07777) << " instead of " << mode;
    EXPECT_EQ(after.st_uid, owner);
    EXPECT_EQ(after.st_gid, group);
    EXPECT_TRUE(fs::exists(dir / "summary.json"));
    // Through the program too.
    const auto run = run_cli(kShortRun + dir.string());
    ASSERT_EQ(run.exit_code, 0) << run.output;
    EXPECT_EQ(stat_of(dir).st_mode & 07777, mode);
    EXPECT_EQ(stat_of(dir).st_uid, owner);
    EXPECT_TRUE(fs::exists(dir / "audio.wav"));
}

TEST(OutputDirectory, SpecialFilesInTheWayStopTheRunAndAreKept) {
    ScratchDir scratch("out-special");
    const fs::path dir = scratch.path() / "out";
    ASSERT_EQ(run_cli(kShortRun + dir.string()).exit_code, 0);
    std::ofstream(dir / "notes.txt") << "mine";
    // A FIFO.
    const fs::path fifo = dir / "pipe";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    const auto refused = run_cli(kShortRun + dir.string());
    EXPECT_EQ(refused.exit_code, 2) << refused.output;
    EXPECT_NE(refused.output.find(fifo.string()), std::string::npos) << refused.output;
    EXPECT_NE(refused.output.find("FIFO"), std::string::npos) << refused.output;
    EXPECT_TRUE(fs::is_fifo(fs::symlink_status(fifo)));
    EXPECT_TRUE(fs::exists(dir / "audio.wav")) << "the earlier results must stay";
    EXPECT_THROW(OutputDirectory{dir}, InputError);
    fs::remove(fifo);
    // A socket, even with the name of a file a run writes.
    const fs::path socket_path = dir / "audio.wav";
    fs::remove(socket_path);
    const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
    ASSERT_GE(fd, 0);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    ASSERT_LT(socket_path.string().size(), sizeof address.sun_path);
    socket_path.string().copy(address.sun_path, sizeof address.sun_path - 1);
    ASSERT_EQ(::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address), 0);
    try {
        OutputDirectory out(dir);
        ADD_FAILURE() << "a socket in the output directory was not refused";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(socket_path.string()), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("socket"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(fs::is_socket(fs::symlink_status(socket_path)));
    ::close(fd);
    fs::remove(socket_path);
    // A link to somewhere else with the name of a file the run writes would be replaced.
    fs::remove(dir / "energy.csv");
    fs::create_symlink(scratch.path() / "elsewhere.csv", dir / "energy.csv");
    EXPECT_THROW(OutputDirectory{dir}, InputError);
    EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir / "energy.csv")));
    fs::remove(dir / "energy.csv");
    // With nothing in the way the run goes on, and the user's file is kept.
    ASSERT_EQ(run_cli(kShortRun + dir.string()).exit_code, 0);
    std::ifstream notes(dir / "notes.txt");
    std::string text;
    notes >> text;
    EXPECT_EQ(text, "mine");
}

TEST(OutputDirectory, ASymbolicLinkLeadsToItsFolderAndStaysALink) {
    ScratchDir scratch("out-link");
    const fs::path real = scratch.path() / "real", link = scratch.path() / "latest";
    fs::create_directory(real);
    ASSERT_EQ(::chmod(real.c_str(), 0700), 0);
    fs::create_symlink("real", link);
    const auto run = run_cli(kShortRun + link.string());
    ASSERT_EQ(run.exit_code, 0) << run.output;
    ASSERT_TRUE(fs::is_symlink(fs::symlink_status(link))) << "the link was replaced";
    EXPECT_EQ(fs::read_symlink(link), fs::path("real"));
    EXPECT_TRUE(fs::exists(real / "audio.wav"));
    EXPECT_EQ(stat_of(real).st_mode & 07777, 0700u);
    // A link to nothing is refused and left as it is.
    const fs::path dangling = scratch.path() / "dangling";
    fs::create_symlink("nowhere", dangling);
    const auto refused = run_cli(kShortRun + dangling.string());
    EXPECT_EQ(refused.exit_code, 2) << refused.output;
    EXPECT_NE(refused.output.find("symbolic link"), std::string::npos) << refused.output;
    EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dangling)));
    EXPECT_FALSE(fs::exists(scratch.path() / "nowhere"));
}

TEST(OutputDirectory, APathTooLongForTheRunsFilesIsRefusedBeforeTheRun) {
    ScratchDir scratch("out-long");
    // Under PATH_MAX, but the staging folder beside it and the files inside it are not.
    std::string path = scratch.str();
    while (path.size() < 4040) path += "/" + std::string(std::min<std::size_t>(200, 4040 - path.size()), 'd');
    for (const std::size_t extra : {0, 5, 10}) {
        const std::string out = path + "/" + std::string(extra + 1, 'x');
        ASSERT_LT(out.size(), static_cast<std::size_t>(PATH_MAX));
        const auto start = std::chrono::steady_clock::now();
        // bass-pop for 3 s: tens of seconds of computing if it were run.
        const auto refused = run_cli("run bass-pop --duration 3 -q --out " + out);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        EXPECT_EQ(refused.exit_code, 2) << out.size() << " bytes: " << refused.output;
        EXPECT_NE(refused.output.find("--out"), std::string::npos) << refused.output;
        EXPECT_LT(seconds, 2.0) << "refused only after computing";
        EXPECT_FALSE(fs::exists(scratch.path() / std::string(200, 'd'))) << "created parents left behind";
    }
    // A name longer than the file system allows.
    const auto long_name = run_cli(kShortRun + scratch.str() + "/" + std::string(300, 'n'));
    EXPECT_EQ(long_name.exit_code, 2) << long_name.output;
    EXPECT_NE(long_name.output.find("bytes"), std::string::npos) << long_name.output;
}

// The check and the writers agree: the longest --out the check lets through is written whole,
// its audio file included (the writers open files through the system, whose limits the check
// knows; libsndfile alone would refuse any path over about a kilobyte), whatever the process
// id of the run (the check counts its widest).
TEST(OutputDirectory, TheLongestPathItAcceptsIsWrittenWhole) {
    ScratchDir scratch("out-longest");
    std::string path = scratch.str();
    while (path.size() < 3900) path += "/" + std::string(std::min<std::size_t>(200, 3900 - path.size()), 'd');
    fs::create_directories(path);
    std::string longest;
    for (std::size_t k = 1; k < 200; ++k) {
        const std::string out = path + "/" + std::string(k, 'x');
        try {
            const OutputDirectory probe(out);
            longest = out;
        } catch (const InputError&) {
            break;
        }
    }
    ASSERT_GT(longest.size(), path.size() + 10) << "the check left no room";
    const auto r = run_cli(kShortRun + longest);
    ASSERT_EQ(r.exit_code, 0) << longest.size() << " bytes: " << r.output;
    const int fd = ::open((longest + "/audio.wav").c_str(), O_RDONLY | O_CLOEXEC);
    ASSERT_GE(fd, 0);
    SF_INFO info{};
    SNDFILE* wav = sf_open_fd(fd, SFM_READ, &info, SF_TRUE);
    ASSERT_NE(wav, nullptr) << sf_strerror(nullptr);
    EXPECT_EQ(info.samplerate, 48000);
    EXPECT_NEAR(static_cast<double>(info.frames), 0.005 * 48000.0, 1.0);  // 5 ms at 48 kHz
    sf_close(wav);
    EXPECT_TRUE(fs::is_regular_file(longest + "/results.h5"));
    EXPECT_TRUE(fs::is_regular_file(longest + "/summary.json"));
}

}  // namespace
}  // namespace fretbuzz
