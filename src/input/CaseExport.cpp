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

std::vector<std::filesystem::path> export_builtin_case(std::string_view name, const std::filesystem::path& dir) {
    const std::string text = builtin_case_text(name);  // InputError listing the names
    std::set<std::string> data_files;
    collect_file_names(parse_toml_document(text, std::string(name) + ".toml"), data_files);
    std::vector<std::filesystem::path> written;
    written.push_back(dir / (std::string(name) + ".toml"));
    write_file(written.back(), text);
    for (const std::string& file : data_files) {
        written.push_back(dir / file);
        write_file(written.back(), *find_builtin_file(file));
    }
    return written;
}

}  // namespace fretbuzz
