// `fretbuzz export`: a built-in case and the data files it names, to write out and edit.
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

// The built-in file `name` (a path under cases/), then every built-in data file its text
// names, each file once.
void add_with_data(const std::string& name, std::string_view text, std::set<std::string>& done,
                   std::vector<ExportedFile>& files) {
    if (!done.insert(name).second) return;
    files.push_back({name, std::string(text)});
    std::set<std::string> data_files;
    collect_file_names(parse_toml_document(text, name), data_files);
    for (const std::string& file : data_files)
        if (done.insert(file).second) files.push_back({file, std::string(*find_builtin_file(file))});
}

}  // namespace

std::vector<ExportedFile> builtin_case_files(std::string_view name) {
    std::vector<ExportedFile> files;
    std::set<std::string> done;
    const std::string file = std::string(name) + ".toml";
    const auto strings = find_builtin_file("bridges/" + file);
    if (!strings || !parse_toml_document(*strings, file).contains("bridge")) {
        add_with_data(file, builtin_case_text(name), done, files);  // InputError listing the names
        return files;
    }
    // Strings on a bridge: the case as written beside each one-string case its strings name
    // (at the paths they name them by, so the folder runs as it is) and their data files.
    files.push_back({file, std::string(*strings)});
    const toml::table root = parse_toml_document(*strings, "bridges/" + file);
    if (const toml::array* list = root["string"].as_array())
        for (const toml::node& s : *list) {
            const std::string named = s.at_path("case").value_or(std::string());
            const std::string path = is_builtin_case(named) ? named + ".toml" : named;
            if (const auto text = find_builtin_file(path)) add_with_data(path, *text, done, files);
        }
    return files;
}

}  // namespace fretbuzz
