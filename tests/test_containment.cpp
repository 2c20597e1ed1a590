// Nothing outside its own folders: `fretbuzz export` writes all or nothing and never through
// a link planted in DIR; `fretbuzz clean` of a missing folder says so, and refuses a sweep's
// runs/ that is a link; no temporary file
// outlives the command that made it, however it is killed; a signal while `fretbuzz setup`
// draws its page interrupts the command (exit 130 or 143, nothing committed); a strings case
// names only case files by a stated rule and never echoes another file; an instrument's
// relief without its gap is named as such.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "SetupTestSupport.hpp"
#include "TestSupport.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/BuiltinFiles.hpp"
#include "fretbuzz/input/InstrumentFile.hpp"

extern char** environ;

namespace fretbuzz {
namespace {

namespace fs = std::filesystem;
using testing::run_cli;
using testing::ScratchDir;

std::string read_text(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

std::set<std::string> tree(const fs::path& dir) {
    std::set<std::string> names;
    std::error_code ec;
    for (const auto& e : fs::recursive_directory_iterator(dir, ec))
        names.insert(e.path().lexically_relative(dir).string());
    return names;
}

// The CLI in a process group of its own, with more variables in its environment and, when
// asked, a limit on the size of the files it writes (a disk that fills at that size).
class Command {
public:
    Command(const std::vector<std::string>& arguments, const fs::path& log, const std::vector<std::string>& env = {},
            rlim_t file_size_limit = RLIM_INFINITY) {
        std::vector<std::string> all{FRETBUZZ_CLI};
        all.insert(all.end(), arguments.begin(), arguments.end());
        std::vector<std::string> variables = env;
        for (char** e = environ; *e != nullptr; ++e) variables.emplace_back(*e);
        std::vector<char*> argv, envp;
        for (std::string& a : all) argv.push_back(a.data());
        for (std::string& v : variables) envp.push_back(v.data());
        argv.push_back(nullptr);
        envp.push_back(nullptr);
        pid_ = ::fork();
        if (pid_ == 0) {
            ::setpgid(0, 0);
            const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
            ::dup2(fd, 1);
            ::dup2(fd, 2);
            if (file_size_limit != RLIM_INFINITY) {
                const rlimit limit{file_size_limit, file_size_limit};
                ::setrlimit(RLIMIT_FSIZE, &limit);
                ::signal(SIGXFSZ, SIG_IGN);  // a write past the limit fails with EFBIG, as on a full disk
            }
            ::execve(argv[0], argv.data(), envp.data());
            ::_exit(127);
        }
    }
    void signal(int s) const { ::kill(pid_, s); }
    void signal_group(int s) const { ::kill(-pid_, s); }
    int wait() const {
        int status = 0;
        ::waitpid(pid_, &status, 0);
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }

private:
    pid_t pid_ = -1;
};

// An interpreter that only says it started, then waits: a Python child caught mid-work.
fs::path waiting_interpreter(const fs::path& dir) {
    const fs::path script = dir / "python-that-waits";
    std::ofstream(script) << "#!/bin/sh\necho $$ > " << (dir / "started").string() << "\nexec sleep 60\n";
    fs::permissions(script, fs::perms::owner_all);
    return script;
}

bool wait_for_file(const fs::path& path, double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
        if (fs::exists(path) && !read_text(path).empty()) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
}

// --- export -------------------------------------------------------------------------

TEST(Export, ALinkPlantedInTheFolderIsNeverFollowed) {
    ScratchDir scratch("export-links");
    const fs::path victim = scratch.path() / "victim", out = scratch.path() / "out";
    fs::create_directories(victim / "folder");
    fs::create_directories(out);
    std::ofstream(victim / "precious.toml") << "mine\n";
    // The case's own name, and a folder the export writes into, each a link out of DIR.
    fs::create_symlink("../victim/precious.toml", out / "strings-on-a-bridge.toml");
    auto r = run_cli("export strings-on-a-bridge " + out.string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("strings-on-a-bridge.toml exists (a symbolic link)"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("export DIR"), std::string::npos) << r.output;
    EXPECT_EQ(read_text(victim / "precious.toml"), "mine\n");

    const fs::path out2 = scratch.path() / "out2";
    fs::create_directories(out2);
    fs::create_directory_symlink("../victim/folder", out2 / "bridges");
    r = run_cli("export sitar-taraf " + out2.string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("bridges exists (a symbolic link)"), std::string::npos) << r.output;
    EXPECT_TRUE(fs::is_empty(victim / "folder"));
    EXPECT_EQ(tree(out2), std::set<std::string>{"bridges"});
    EXPECT_EQ(tree(scratch.path()).count("out2/bridges"), 1u);
    for (const auto& name : tree(scratch.path())) EXPECT_EQ(name.find(".fretbuzz"), std::string::npos) << name;
}

TEST(Export, AddsItsFilesBesideTheFolderOwnAndRunsFromThere) {
    ScratchDir scratch("export-beside");
    const fs::path out = scratch.path() / "out";
    fs::create_directories(out);
    std::ofstream(out / "notes.txt") << "my notes\n";
    const auto r = run_cli("export sitar-taraf " + out.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(read_text(out / "notes.txt"), "my notes\n");
    EXPECT_EQ(read_text(out / "bridges" / "taraf-string.toml"), std::string(*find_builtin_file("bridges/taraf-string.toml")));
    EXPECT_EQ(run_cli("show " + (out / "sitar-taraf.toml").string()).exit_code, 0);
    // Again into the same folder: its files are there, none is replaced.
    const auto again = run_cli("export sitar-taraf " + out.string());
    EXPECT_EQ(again.exit_code, 2) << again.output;
    EXPECT_NE(again.output.find("exists"), std::string::npos) << again.output;
}

// A disk that fills while the export writes: exit 1 naming the file, and nothing left at all.
void expect_nothing_left_by_a_full_disk(const fs::path& disk, rlim_t file_size_limit, const std::string& what) {
    SCOPED_TRACE(what);
    const fs::path out = disk / "out", log = disk.parent_path() / "log";
    const int status = Command({"export", "sitar-taraf", out.string()}, log, {}, file_size_limit).wait();
    const std::string message = read_text(log);
    EXPECT_EQ(status, 1) << message;
    EXPECT_NE(message.find("cannot write"), std::string::npos) << message;
    EXPECT_EQ(tree(disk), std::set<std::string>{}) << "left behind on a full disk";
}

TEST(Export, AFullDiskLeavesNothingBehind) {
    ScratchDir scratch("export-full");
    // A file-size limit (any user): the first file larger than 2 KiB fails as on a full disk.
    fs::create_directories(scratch.path() / "limited");
    expect_nothing_left_by_a_full_disk(scratch.path() / "limited", 2048, "a 2 KiB file-size limit");
    // A real full disk where this user may mount one (root): an 8 KiB tmpfs.
    const fs::path disk = scratch.path() / "disk";
    fs::create_directories(disk);
    if (::mount("tmpfs", disk.c_str(), "tmpfs", 0, "size=8k") != 0) GTEST_SKIP() << "no tmpfs here (needs root)";
    expect_nothing_left_by_a_full_disk(disk, RLIM_INFINITY, "an 8 KiB tmpfs");
    ::umount(disk.c_str());
}

// --- clean --------------------------------------------------------------------------

TEST(Clean, AMissingFolderExitsTwoNamingIt) {
    ScratchDir scratch("clean-missing");
    const auto r = run_cli("clean " + (scratch.path() / "no-such-folder").string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("no-such-folder: no such folder"), std::string::npos) << r.output;
    std::ofstream(scratch.path() / "a-file") << "x";
    EXPECT_EQ(run_cli("clean " + (scratch.path() / "a-file").string()).exit_code, 2);
}

TEST(Clean, ASweepWhoseRunsFolderIsALinkIsRefusedAndNothingDeleted) {
    ScratchDir scratch("clean-sweep-link");
    const fs::path sweep = scratch.path() / "sweep", victim = scratch.path() / "victim";
    fs::create_directories(sweep);
    fs::create_directories(victim);
    std::ofstream(sweep / "sweep.toml") << "# a sweep's folder\n";
    std::ofstream(victim / "mine.json.tmp-4242-1") << "mine\n";  // named as a sweep's temporary file
    fs::create_directory_symlink("../victim", sweep / "runs");
    const auto r = run_cli("clean " + sweep.string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("runs is a symbolic link"), std::string::npos) << r.output;
    EXPECT_EQ(read_text(victim / "mine.json.tmp-4242-1"), "mine\n");
}

// --- temporary files and signals around the Python child ------------------------------

TEST(PythonChild, NoScriptStaysInTheTemporaryFolderWhenTheCommandIsKilled) {
    ScratchDir scratch("script-kill");
    const fs::path tmp = scratch.path() / "tmp", study = scratch.path() / "study";
    fs::create_directories(tmp);
    fs::create_directories(study);
    std::ofstream(study / ".fretbuzz-studio.lock") << "";
    // `fretbuzz clean STUDY` runs the package's studio.clean in the interpreter; it is killed
    // (SIGKILL: no chance to clean up) while that child has the script and has not read it.
    const fs::path python = waiting_interpreter(scratch.path());
    Command command({"clean", study.string()}, scratch.path() / "log",
                    {"FRETBUZZ_PYTHON=" + python.string(), "TMPDIR=" + tmp.string()});
    ASSERT_TRUE(wait_for_file(scratch.path() / "started", 30)) << read_text(scratch.path() / "log");
    command.signal(SIGKILL);
    command.wait();
    EXPECT_EQ(tree(tmp), std::set<std::string>{}) << "a temporary file outlived the command";
}

TEST(PythonChild, ASignalWhileThePageIsDrawnInterruptsSetupAndCommitsNothing) {
    ScratchDir scratch("setup-page-signal");
    const fs::path python = waiting_interpreter(scratch.path());
    // SIGTERM to the command; Ctrl-C (SIGINT to its process group, as a terminal sends it).
    for (const int sig : {SIGTERM, SIGINT}) {
        SCOPED_TRACE(sig == SIGTERM ? "SIGTERM" : "SIGINT to the group");
        fs::remove(scratch.path() / "started");
        const fs::path out = scratch.path() / "out", log = scratch.path() / "log";
        Command command({"setup", "jazz-bass", "--strings", "G", "--frets", "0", "--ensemble", "1", "--fs", "300kHz",
                         "--duration", "0.05", "--strength", "medium", "--quiet", "--out", out.string()},
                        log, {"FRETBUZZ_PYTHON=" + python.string()});
        ASSERT_TRUE(wait_for_file(scratch.path() / "started", 120)) << read_text(log);
        if (sig == SIGTERM)
            command.signal(SIGTERM);
        else
            command.signal_group(SIGINT);
        const int status = command.wait();
        const std::string message = read_text(log);
        EXPECT_EQ(status, 128 + sig) << message;
        EXPECT_FALSE(fs::exists(out)) << "committed after an interruption";
        EXPECT_EQ(message.find("python3-jinja2"), std::string::npos) << "a false warning: " << message;
        EXPECT_NE(message.find(sig == SIGTERM ? "interrupted by SIGTERM" : "interrupted by SIGINT"), std::string::npos)
            << message;
        for (const auto& name : tree(scratch.path())) EXPECT_EQ(name.find(".fretbuzz"), std::string::npos) << name;
    }
}

// --- which files a strings case may name ------------------------------------------------

class StringsCaseReference : public ::testing::Test {
protected:
    void SetUp() override {
        fs::create_directories(folder());
        fs::create_directories(scratch_.path() / "outside");
        // Another file's content, with a ':' where a TOML parser stops (as /etc/shadow's).
        std::ofstream(scratch_.path() / "outside" / "secret.toml") << "root:SECRET-HASH:19000:0:99999:7:::\n";
        std::ofstream(scratch_.path() / "outside" / "secret") << "root:SECRET-HASH:19000:0:99999:7:::\n";
        std::ofstream(folder() / "notes.txt") << "root:SECRET-HASH:19000\n";
        std::ofstream(folder() / "p.toml") << *find_builtin_file("bridges/pair-string.toml");
        fs::create_directories(folder() / "sub");
        std::ofstream(folder() / "sub" / "q.toml") << *find_builtin_file("bridges/pair-string.toml");
    }
    fs::path folder() const { return scratch_.path() / "case"; }
    // `fretbuzz show` of a strings case whose one string names `named`.
    testing::CommandResult show(const std::string& named) {
        std::ofstream(folder() / "s.toml") << "name = \"x\"\n[run]\nfs = 96000\nduration = 0.01\n[bridge]\n"
                                              "[[bridge.mode]]\nmass_kg = 0.005\nfrequency_hz = 300.0\n"
                                              "participation = [1.0]\n[[string]]\nname = \"a\"\ncase = \""
                                           << named << "\"\n";
        return run_cli("show " + (folder() / "s.toml").string());
    }
    ScratchDir scratch_{"strings-reference"};
};

TEST_F(StringsCaseReference, OnlyCaseFilesInsideItsFolderOrBuiltInOnes) {
    const fs::path fifo = folder() / "fifo.toml";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    fs::create_symlink("../outside/secret.toml", folder() / "link.toml");
    { std::ofstream(folder() / "big.toml") << "name = \"big\"\n"; }
    fs::resize_file(folder() / "big.toml", 5u << 20);  // sparse
    const struct {
        std::string named, why;
    } refused[] = {
        {(scratch_.path() / "outside" / "secret").string(), "an absolute path"},
        {"/etc/shadow", "an absolute path"},
        {"../outside/secret.toml", "'..'"},
        {"sub/../../outside/secret.toml", "'..'"},
        {"notes.txt", "not a .toml file"},
        {"link.toml", "outside this case's folder"},
        {"fifo.toml", "not a regular file"},
        {"big.toml", "larger than 4 MiB"},
        {"missing.toml", "no such file"},
        {"", "empty"},
    };
    const auto start = std::chrono::steady_clock::now();
    for (const auto& c : refused) {
        SCOPED_TRACE(c.named);
        const auto r = show(c.named);
        EXPECT_EQ(r.exit_code, 2) << r.output;
        EXPECT_NE(r.output.find("string[0].case = \"" + c.named + "\""), std::string::npos) << r.output;
        EXPECT_NE(r.output.find(c.why), std::string::npos) << r.output;
        // Nothing of another file: neither its content nor where its parse failed.
        EXPECT_EQ(r.output.find("SECRET"), std::string::npos) << r.output;
        EXPECT_EQ(r.output.find("expected '='"), std::string::npos) << r.output;
        EXPECT_EQ(r.output.find(":1:5"), std::string::npos) << r.output;
    }
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 60.0);
    // What the rule lets through: a case file in the folder or below it, a built-in case by
    // name or by its built-in path.
    for (const std::string named : {"p.toml", "sub/q.toml", "./p.toml", "bass-pluck", "bridges/pair-string.toml"}) {
        const auto r = show(named);
        EXPECT_EQ(r.exit_code, 0) << named << ": " << r.output;
    }
}

// --- the smaller gaps ---------------------------------------------------------------------

TEST(InstrumentRelief, AFretWithoutItsGapIsNamedAsSuch) {
    std::string text = *builtin_instrument_text("jazz-bass");
    const auto at = text.find("[neck.relief]");
    ASSERT_NE(at, std::string::npos);
    const auto end = text.find("\n[", at + 1);
    text.replace(at, end - at, "[neck.relief]\nfret = 8\n");
    try {
        parse_instrument(text, "test.toml", DataSource::builtin());
        ADD_FAILURE() << "accepted a relief fret without its gap";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("neck.relief.fret"), std::string::npos) << what;
        EXPECT_NE(what.find("neck.relief.gap"), std::string::npos) << what;
        EXPECT_EQ(what.find("unknown key"), std::string::npos) << what;
    }
}

}  // namespace
}  // namespace fretbuzz
