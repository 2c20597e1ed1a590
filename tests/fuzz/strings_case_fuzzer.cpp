// libFuzzer target: any bytes as a strings case (strings on a bridge, each [[string]] naming a
// one-string case). Reading, validation and the description `fretbuzz show` prints may refuse
// the input (InputError), never crash, hang or throw anything else; a [[string]] names only
// what the case-reference rule allows (here: built-in cases and files).
#include <cstddef>
#include <cstdint>
#include <string>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/StringsCaseFile.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const fretbuzz::CaseText text{std::string(reinterpret_cast<const char*>(data), size), "fuzz.toml",
                                  fretbuzz::DataSource::builtin()};
    try {
        const fretbuzz::StringsCase c = fretbuzz::parse_strings_case(text);
        c.validate();
        (void)fretbuzz::describe_strings_case(c);
    } catch (const fretbuzz::InputError&) {
    }
    return 0;
}
