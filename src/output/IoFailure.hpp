#pragma once
// A failed system call on an output file, as the writers report it (exit 1): what was tried,
// the path, and the system's reason.
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace fretbuzz {

[[noreturn]] inline void io_failure(const std::string& what, const std::filesystem::path& path, int error) {
    throw std::runtime_error("cannot " + what + " " + path.string() + ": " + std::strerror(error));
}

}  // namespace fretbuzz
