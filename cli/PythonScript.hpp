#pragma once
// Runs a Python script carried inside the binary: it is held in an unnamed in-memory file
// (nothing in the temporary folder, whatever kills which process) and run by Debian's
// interpreter (/usr/bin/python3, which has numpy, matplotlib and h5py), or by the one named
// in $FRETBUZZ_PYTHON.
#include <string>
#include <string_view>
#include <vector>

namespace fretbuzz::cli {

std::string_view plot_script();  // python/fretbuzz/plots.py, embedded at build time

// The script's exit status; throws std::runtime_error if the interpreter cannot be started.
// A script ended by SIGINT or SIGTERM (130, 143), or a SIGTERM sent to this process while it
// runs, is recorded as a stop (request_stop): the caller's commit then throws Interrupted.
int run_python_script(std::string_view script, const std::vector<std::string>& arguments);

// Runs main(arguments) of a module of the fretbuzz Python package (e.g. "sweeps"); its exit
// status. The package is looked for in $FRETBUZZ_PYTHONPATH first, then where this program
// belongs: its build's module when it runs from the build tree, else the package installed
// with it (<prefix>/<libdir>/fretbuzz/python, found from /proc/self/exe), then the
// interpreter's own path.
std::string package_directory();
int run_package_main(const std::string& module, const std::vector<std::string>& arguments);

}  // namespace fretbuzz::cli
