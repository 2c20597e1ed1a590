#include "PythonScript.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "fretbuzz/Error.hpp"

extern char** environ;

namespace fretbuzz::cli {

namespace {

std::string interpreter() {
    const char* chosen = std::getenv("FRETBUZZ_PYTHON");
    return chosen != nullptr && *chosen != '\0' ? chosen : "/usr/bin/python3";
}

// The script in an unnamed file (memfd_create): it is in no folder, so nothing can stay
// behind whichever process is killed when. The interpreter reads it from the descriptor it
// inherits.
class ScriptFile {
public:
    explicit ScriptFile(std::string_view text) {
        fd_ = ::memfd_create("fretbuzz-script.py", MFD_CLOEXEC);
        if (fd_ < 0) throw std::runtime_error("cannot hold the Python script in memory: " + std::string(std::strerror(errno)));
        std::size_t done = 0;
        while (done < text.size()) {
            const ssize_t n = ::write(fd_, text.data() + done, text.size() - done);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) {
                const int error = errno;
                ::close(fd_);
                throw std::runtime_error("cannot hold the Python script in memory: " + std::string(std::strerror(error)));
            }
            done += static_cast<std::size_t>(n);
        }
        // The interpreter reads it through this same open file: from its start.
        if (::lseek(fd_, 0, SEEK_SET) != 0) {
            const int error = errno;
            ::close(fd_);
            throw std::runtime_error("cannot hold the Python script in memory: " + std::string(std::strerror(error)));
        }
    }
    ~ScriptFile() { ::close(fd_); }
    ScriptFile(const ScriptFile&) = delete;
    ScriptFile& operator=(const ScriptFile&) = delete;
    int fd() const { return fd_; }

private:
    int fd_ = -1;
};

// The interpreter is given this loader and the script's descriptor: it reads the script,
// closes the descriptor (the script's own children do not inherit it), then runs it as
// __main__. `-c` would put the current folder first on the module path: the scripts import
// only the package and the interpreter's own modules.
constexpr std::string_view kLoader =
    "import os, sys\n"
    "fd = int(sys.argv.pop(1))\n"
    "with open(fd, encoding='utf-8', closefd=True) as f:\n"
    "    source = f.read()\n"
    "sys.argv[0] = 'fretbuzz-script.py'\n"
    "if sys.path and sys.path[0] == '':\n"
    "    del sys.path[0]\n"
    "exec(compile(source, sys.argv[0], 'exec'), {'__name__': '__main__', '__builtins__': __builtins__})\n";

// While the interpreter runs, Ctrl-C is its to handle (the terminal sends SIGINT to both);
// a SIGTERM sent to this process alone is passed on to it. Either is also recorded as a stop
// (request_stop): what the command was doing is interrupted, and a command that would commit
// its results after the script commits nothing (exit 130 or 143).
volatile std::sig_atomic_t child_pid = 0;
extern "C" void forward_signal(int signal) {
    request_stop(signal);
    if (child_pid > 0) ::kill(static_cast<pid_t>(child_pid), signal);
}
extern "C" void record_signal(int signal) { request_stop(signal); }

class SignalsToChild {
public:
    SignalsToChild() {
        struct sigaction record {}, forward {};
        record.sa_handler = record_signal;
        forward.sa_handler = forward_signal;
        record.sa_flags = SA_RESTART;
        forward.sa_flags = SA_RESTART;
        sigemptyset(&record.sa_mask);
        sigemptyset(&forward.sa_mask);
        ::sigaction(SIGINT, &record, &int_);
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

// fork and exec, with the child bound to this process: the kernel sends it SIGTERM when this
// process ends, however it ends (SIGKILL included), so no server or plot outlives the
// command. Returns the child's pid; throws if the interpreter cannot be started.
pid_t start_child(const std::string& python, std::vector<char*>& argv, int script_fd) {
    int report[2];
    if (::pipe2(report, O_CLOEXEC) != 0) throw std::runtime_error(std::string("cannot start ") + python + ": " + std::strerror(errno));
    struct sigaction defaults {};
    defaults.sa_handler = SIG_DFL;
    sigemptyset(&defaults.sa_mask);
    const pid_t parent = ::getpid();
    const pid_t pid = ::fork();
    if (pid == 0) {
        // The child: only async-signal-safe calls until exec.
        ::close(report[0]);
        ::prctl(PR_SET_PDEATHSIG, SIGTERM);
        if (::getppid() != parent) ::_exit(127);  // this process ended before the line above
        ::fcntl(script_fd, F_SETFD, 0);  // the interpreter reads the script from it
        // The interpreter starts with the default actions for SIGINT and SIGTERM.
        ::sigaction(SIGINT, &defaults, nullptr);
        ::sigaction(SIGTERM, &defaults, nullptr);
        ::execve(python.c_str(), argv.data(), environ);
        const int error = errno;
        [[maybe_unused]] const ssize_t n = ::write(report[1], &error, sizeof error);
        ::_exit(127);
    }
    const int fork_error = errno;
    ::close(report[1]);
    if (pid < 0) {
        ::close(report[0]);
        throw std::runtime_error("cannot start " + python + ": " + std::strerror(fork_error));
    }
    int error = 0;
    ssize_t n = 0;
    do n = ::read(report[0], &error, sizeof error);
    while (n < 0 && errno == EINTR);
    ::close(report[0]);
    if (n == static_cast<ssize_t>(sizeof error)) {
        ::waitpid(pid, nullptr, 0);
        throw std::runtime_error("cannot run " + python + " (" + std::strerror(error) +
                                 "); install python3-matplotlib python3-numpy python3-h5py or set FRETBUZZ_PYTHON");
    }
    return pid;
}

}  // namespace

int run_python_script(std::string_view script, const std::vector<std::string>& arguments) {
    const ScriptFile file(script);
    const std::string python = interpreter();
    std::vector<std::string> words{python, "-c", std::string(kLoader), std::to_string(file.fd())};
    words.insert(words.end(), arguments.begin(), arguments.end());
    std::vector<char*> argv;
    for (std::string& w : words) argv.push_back(w.data());
    argv.push_back(nullptr);
    const SignalsToChild signals;
    // No shell in between: directory names reach the script verbatim.
    const pid_t pid = start_child(python, argv, file.fd());
    child_pid = pid;
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0) {
        if (errno != EINTR) throw std::runtime_error("waiting for " + python + " failed");
    }
    // A script ended by Ctrl-C or SIGTERM (the signal itself, or Python's 130/143 after its
    // KeyboardInterrupt) interrupted the command, whichever process the signal reached.
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    if (code == 128 + SIGINT || code == 128 + SIGTERM) request_stop(code - 128);
    return code;
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
