#include "fretbuzz/input/BuiltinFiles.hpp"

#include <algorithm>

namespace fretbuzz {

std::optional<std::string_view> find_builtin_file(std::string_view name) {
    const auto& files = builtin_files();
    const auto it = std::find_if(files.begin(), files.end(), [&](const EmbeddedFile& f) { return name == f.name; });
    if (it == files.end()) return std::nullopt;
    return it->text();
}

}  // namespace fretbuzz
