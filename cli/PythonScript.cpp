#include "PythonScript.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>

extern char** environ;

namespace fretbuzz::cli {

namespace {

std::string interpreter() {
    const char* chosen = std::getenv("FRETBUZZ_PYTHON");
    return chosen != nullptr && *chosen != '\0' ? chosen : "/usr/bin/python3";
}

// A temporary file holding the script, removed when this goes out of scope.
class TemporaryScript {
public:
    explicit TemporaryScript(std::string_view text) {
        path_ = (std::filesystem::temp_directory_path() / "fretbuzz-script-XXXXXX.py").string();
        const int fd = ::mkstemps(path_.data(), 3);
        if (fd < 0) throw std::runtime_error("cannot create a temporary file for the plotting script: " + std::string(std::strerror(errno)));
        std::size_t done = 0;
        while (done < text.size()) {
            const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
            if (n <= 0) {
                ::close(fd);
                ::unlink(path_.c_str());
                throw std::runtime_error("cannot write the plotting script to " + path_);
            }
            done += static_cast<std::size_t>(n);
        }
        ::close(fd);
    }
    ~TemporaryScript() { ::unlink(path_.c_str()); }
    TemporaryScript(const TemporaryScript&) = delete;
    TemporaryScript& operator=(const TemporaryScript&) = delete;
    const std::string& path() const { return path_; }

private:
    std::string path_;
};

// While the interpreter runs, Ctrl-C is its to handle (the terminal sends SIGINT to both:
// this process ignores it and reports the script's own exit, 130 with its message), and a
// SIGTERM sent to this process alone is passed on to it.
volatile std::sig_atomic_t child_pid = 0;
extern "C" void forward_signal(int signal) {
    if (child_pid > 0) ::kill(static_cast<pid_t>(child_pid), signal);
}

class SignalsToChild {
public:
    SignalsToChild() {
        struct sigaction ignore {}, forward {};
        ignore.sa_handler = SIG_IGN;
        forward.sa_handler = forward_signal;
        sigemptyset(&ignore.sa_mask);
        sigemptyset(&forward.sa_mask);
        ::sigaction(SIGINT, &ignore, &int_);
        ::sigaction(SIGTERM, &forward, &term_);
    }
    ~SignalsToChild() {
        ::sigaction(SIGINT, &int_, nullptr);
        ::sigaction(SIGTERM, &term_, nullptr);
        child_pid = 0;
    }
    SignalsToChild(const SignalsToChild&) = delete;
    SignalsToChild& operator=(const SignalsToChild&) = delete;

private:
    struct sigaction int_ {}, term_ {};
};

}  // namespace

int run_python_script(std::string_view script, const std::vector<std::string>& arguments) {
    const TemporaryScript file(script);
    const std::string python = interpreter();
    std::vector<std::string> words{python, file.path()};
    words.insert(words.end(), arguments.begin(), arguments.end());
    std::vector<char*> argv;
    for (std::string& w : words) argv.push_back(w.data());
    argv.push_back(nullptr);
    pid_t pid = 0;
    // The interpreter starts with the default actions for SIGINT and SIGTERM, whatever this
    // process does with them.
    posix_spawnattr_t attributes;
    posix_spawnattr_init(&attributes);
    sigset_t defaults;
    sigemptyset(&defaults);
    sigaddset(&defaults, SIGINT);
    sigaddset(&defaults, SIGTERM);
    posix_spawnattr_setsigdefault(&attributes, &defaults);
    posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGDEF);
    const SignalsToChild signals;
    // No shell in between: directory names reach the script verbatim.
    const int error = ::posix_spawn(&pid, python.c_str(), nullptr, &attributes, argv.data(), environ);
    posix_spawnattr_destroy(&attributes);
    child_pid = pid;
    if (error != 0)
        throw std::runtime_error("cannot run " + python + " (" + std::strerror(error) +
                                 "); install python3-matplotlib python3-numpy python3-h5py or set FRETBUZZ_PYTHON");
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0) {
        if (errno != EINTR) throw std::runtime_error("waiting for " + python + " failed");
    }
    if (WIFEXITED(status)) return WEXITSTATUS(status);
    return 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

std::string package_directory() {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path program = fs::read_symlink("/proc/self/exe", ec);
    if (ec) return FRETBUZZ_BUILD_PYTHON_DIR;
    const fs::path here = program.parent_path();
    if (fs::equivalent(here, fs::path(FRETBUZZ_BUILD_CLI_DIR), ec)) return FRETBUZZ_BUILD_PYTHON_DIR;
    return (here / FRETBUZZ_INSTALLED_PYTHON_DIR).lexically_normal().string();
}

int run_package_main(const std::string& module, const std::vector<std::string>& arguments) {
    const std::string script =
        "import importlib, sys\n"
        "sys.path[:0] = [p for p in sys.argv.pop(1).split(':') if p]\n"
        "module = importlib.import_module('fretbuzz.' + sys.argv.pop(1))\n"
        "sys.exit(module.main(sys.argv[1:]))\n";
    std::string paths = package_directory();
    if (const char* extra = std::getenv("FRETBUZZ_PYTHONPATH")) paths = std::string(extra) + ":" + paths;
    std::vector<std::string> args{paths, module};
    args.insert(args.end(), arguments.begin(), arguments.end());
    return run_python_script(script, args);
}

}  // namespace fretbuzz::cli
