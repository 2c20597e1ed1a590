#include "CaseReference.hpp"

#include <filesystem>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/BuiltinFiles.hpp"
#include "fretbuzz/input/TextFile.hpp"

namespace fretbuzz {

namespace fs = std::filesystem;

namespace {

constexpr std::string_view kRule =
    "a string's case is a built-in case's name or a .toml case file inside this case's folder, named by a relative "
    "path without '..'";

[[noreturn]] void refuse(const std::string& named, const std::string& key, const std::string& why) {
    throw InputError(key + " = \"" + named + "\": " + why + "; " + std::string(kRule));
}

}  // namespace

std::string read_case_reference(const std::string& named, const std::string& key, const DataSource& data) {
    if (is_builtin_case(named)) return builtin_case_text(named);
    const fs::path given(named);
    if (named.empty()) refuse(named, key, "empty");
    if (given.is_absolute()) refuse(named, key, "an absolute path");
    for (const fs::path& part : given)
        if (part == "..") refuse(named, key, "a path out of the folder ('..')");
    if (given.extension() != ".toml") refuse(named, key, "not a .toml file");
    if (data.is_builtin()) {
        if (const auto text = find_builtin_file(named)) return std::string(*text);
        refuse(named, key, "no such built-in case file");
    }
    std::error_code ec;
    const fs::path folder = fs::canonical(data.directory().empty() ? fs::path(".") : data.directory(), ec);
    if (ec) throw InputError(key + " = \"" + named + "\": cannot resolve this case's folder (" + ec.message() + ")");
    const fs::path path = folder / given;
    if (!fs::exists(fs::symlink_status(path, ec))) {
        if (const auto text = find_builtin_file(named)) return std::string(*text);  // a copied case
        refuse(named, key, "no such file in " + folder.string() + ", nor a built-in one");
    }
    // Links inside the folder are followed only to files inside it.
    const fs::path real = fs::canonical(path, ec);
    if (ec) refuse(named, key, "cannot be resolved (" + ec.message() + ")");
    const fs::path inside = real.lexically_relative(folder);
    if (inside.empty() || *inside.begin() == "..") refuse(named, key, "a link to a file outside this case's folder");
    return read_text_file(real, key + " = \"" + named + "\"", kMaxCaseFileBytes);
}

}  // namespace fretbuzz
