// `fretbuzz export`: a built-in case and the data files it names, written out to edit.
#include <fstream>
#include <set>
#include <stdexcept>

#include "TomlSection.hpp"
#include "fretbuzz/input/BuiltinFiles.hpp"
#include "fretbuzz/input/CaseExport.hpp"
#include "fretbuzz/input/StringsCaseFile.hpp"

namespace fretbuzz {

namespace {

// Every string value anywhere in the document that names a built-in data file: whatever
// key names it (a mode table, an obstacle profile, a modal file, keys added later).
void collect_file_names(const toml::node& node, std::set<std::string>& names) {
    if (const auto* table = node.as_table()) {
        for (const auto& [key, value] : *table) collect_file_names(value, names);
    } else if (const auto* array = node.as_array()) {
        for (const toml::node& value : *array) collect_file_names(value, names);
    } else if (const auto* text = node.as_string()) {
        if (text->get().find('/') != std::string::npos && find_builtin_file(text->get())) names.insert(text->get());
    }
}

void write_file(const std::filesystem::path& path, std::string_view text) {
    std::filesystem::create_directories(path.parent_path());
    std::ofstream out(path, std::ios::binary);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.close();
    if (!out) throw std::runtime_error("cannot write " + path.string());
}

}  // namespace

std::set<std::string> case_keys_looked_up(std::string_view toml_text, const std::string& source_name,
                                          const DataSource& data) {
    std::set<std::string> keys;
    const KeyLogScope scope(keys);
    if (parse_toml_document(toml_text, source_name).contains("bridge"))
        parse_strings_case({std::string(toml_text), source_name, data});  // strings on a bridge
    else
        parse_case(toml_text, source_name, data);
    return keys;
}

namespace {

// Writes the built-in file `name` (a path under cases/) as DIR/name, then every built-in data
// file its text names, each file once.
void write_with_data(const std::filesystem::path& dir, const std::string& name, std::string_view text,
                     std::set<std::string>& done, std::vector<std::filesystem::path>& written) {
    if (!done.insert(name).second) return;
    written.push_back(dir / name);
    write_file(written.back(), text);
    std::set<std::string> data_files;
    collect_file_names(parse_toml_document(text, name), data_files);
    for (const std::string& file : data_files)
        if (done.insert(file).second) {
            written.push_back(dir / file);
            write_file(written.back(), *find_builtin_file(file));
        }
}

}  // namespace

std::vector<std::filesystem::path> export_builtin_case(std::string_view name, const std::filesystem::path& dir) {
    std::vector<std::filesystem::path> written;
    std::set<std::string> done;
    const std::string file = std::string(name) + ".toml";
    const auto strings = find_builtin_file("bridges/" + file);
    if (!strings || !parse_toml_document(*strings, file).contains("bridge")) {
        write_with_data(dir, file, builtin_case_text(name), done, written);  // InputError listing the names
        return written;
    }
    // Strings on a bridge: the case as written beside each one-string case its strings name
    // (at the paths they name them by, so the folder runs as it is) and their data files.
    written.push_back(dir / file);
    write_file(written.back(), *strings);
    const toml::table root = parse_toml_document(*strings, "bridges/" + file);
    if (const toml::array* list = root["string"].as_array())
        for (const toml::node& s : *list) {
            const std::string named = s.at_path("case").value_or(std::string());
            const std::string path = is_builtin_case(named) ? named + ".toml" : named;
            if (const auto text = find_builtin_file(path)) write_with_data(dir, path, *text, done, written);
        }
    return written;
}

}  // namespace fretbuzz
