#pragma once
// The built-in case files (cases/*.toml) and the data they use (cases/data/*.csv),
// compiled into the library by cmake/EmbedFiles.cmake.
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace fretbuzz {

struct EmbeddedFile {
    const char* name;
    const char* data;
    std::size_t size;
    std::string_view text() const { return {data, size}; }
};

const std::vector<EmbeddedFile>& builtin_files();
std::optional<std::string_view> find_builtin_file(std::string_view name);

}  // namespace fretbuzz
