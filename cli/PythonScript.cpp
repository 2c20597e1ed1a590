#include "PythonScript.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
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
    // No shell in between: directory names reach the script verbatim.
    const int error = ::posix_spawn(&pid, python.c_str(), nullptr, nullptr, argv.data(), environ);
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

int run_package_main(const std::string& module, const std::vector<std::string>& arguments) {
    const std::string script =
        "import importlib, sys\n"
        "sys.path[:0] = [p for p in sys.argv.pop(1).split(':') if p]\n"
        "module = importlib.import_module('fretbuzz.' + sys.argv.pop(1))\n"
        "sys.exit(module.main(sys.argv[1:]))\n";
    std::string paths = FRETBUZZ_PYTHON_DIRS;
    if (const char* extra = std::getenv("FRETBUZZ_PYTHONPATH")) paths = std::string(extra) + ":" + paths;
    std::vector<std::string> args{paths, module};
    args.insert(args.end(), arguments.begin(), arguments.end());
    return run_python_script(script, args);
}

}  // namespace fretbuzz::cli
