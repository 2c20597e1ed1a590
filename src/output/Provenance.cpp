#include "fretbuzz/output/Provenance.hpp"

#include <nettle/sha2.h>
#include <sys/utsname.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <ctime>
#include <stdexcept>
#include <nlohmann/json.hpp>

#include "JsonText.hpp"
#include "fretbuzz/Version.hpp"

namespace fretbuzz {

namespace {

std::string utc_now() {
    const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
    std::tm utc{};
    gmtime_r(&now, &utc);
    std::array<char, 32> text{};
    std::strftime(text.data(), text.size(), "%Y-%m-%dT%H:%M:%SZ", &utc);
    return text.data();
}

std::string platform() {
    std::string result;
    utsname u{};
    if (uname(&u) == 0) result = std::string(u.sysname) + " " + u.release + " " + u.machine;
#if defined(__clang__)
    result += ", clang " __clang_version__;
#elif defined(__GNUC__)
    result += ", gcc " __VERSION__;
#endif
    return result;
}

}  // namespace

Provenance current_provenance(std::string command_line) {
    return {std::string(version), utc_now(), std::move(command_line), platform()};
}

std::string sha256_hex(std::string_view bytes) {
    // Nettle, not OpenSSL: one small library with nothing to set up, where libcrypto cost
    // more to load and initialise (relocations, its configuration file) than the rest of a
    // short run's start.
    sha256_ctx context{};
    sha256_init(&context);
    sha256_update(&context, bytes.size(), reinterpret_cast<const std::uint8_t*>(bytes.data()));
    std::array<std::uint8_t, SHA256_DIGEST_SIZE> digest{};
    sha256_digest(&context, digest.size(), digest.data());
    static constexpr char kHex[] = "0123456789abcdef";
    std::string hex;
    hex.reserve(2 * digest.size());
    for (const std::uint8_t byte : digest) {
        hex += kHex[byte >> 4];
        hex += kHex[byte & 0xf];
    }
    return hex;
}

std::string provenance_json(const Provenance& p, const Case& c) {
    nlohmann::ordered_json modes = nlohmann::ordered_json::array();
    std::vector<std::string> source;
    for (std::size_t j = 0; j < c.modes.source.size(); ++j) source.push_back(to_string(c.modes.source[j]));
    const nlohmann::ordered_json json = {
        {"fretbuzz_version", p.version},
        {"created_utc", p.created_utc},
        {"command_line", p.command_line},
        {"platform", p.platform},
        {"case_name", c.name},
        {"case_sha256", sha256_hex(c.source_text)},
        {"case_text", c.source_text},
        {"mode_table",
         {{"frequency_hz", c.modes.frequency_hz}, {"sigma_per_s", c.modes.sigma_per_s}, {"source", source}}},
    };
    return json_text(json);
}

}  // namespace fretbuzz
