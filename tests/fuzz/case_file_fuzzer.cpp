// libFuzzer target: any bytes as a case file. Parsing and validation may refuse the input
// (InputError), never crash, hang or throw anything else.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/CaseFile.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    try {
        const fretbuzz::Case c = fretbuzz::parse_case(text, "fuzz.toml", fretbuzz::DataSource::builtin());
        c.validate();
    } catch (const fretbuzz::InputError&) {
    }
    return 0;
}
