// The real-time floor takes parsed notes: reading note lists and MIDI files (TOML, libsmf,
// files at all) belongs to the input floor, which checks what it reads in one place.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace {

TEST(RealtimeLayer, ReadsNoInputFiles) {
    const std::filesystem::path root = FRETBUZZ_SOURCE_DIR;
    int files = 0;
    for (const auto& folder : {root / "src" / "realtime", root / "include" / "fretbuzz" / "realtime"}) {
        for (const auto& entry : std::filesystem::directory_iterator(folder)) {
            std::ifstream in(entry.path());
            const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
            ++files;
            for (const char* reader : {"TomlSection", "toml++", "<smf.h>", "<fstream>", "parse_toml_document"})
                EXPECT_EQ(text.find(reader), std::string::npos) << entry.path() << " uses " << reader;
        }
    }
    EXPECT_GE(files, 4);
}

}  // namespace
