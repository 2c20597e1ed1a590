#include "JsonText.hpp"

#include <cmath>

#include "fretbuzz/output/CsvWriters.hpp"

namespace fretbuzz {

namespace {

void append_json(std::string& out, const nlohmann::ordered_json& value, int indent, int depth) {
    if (value.is_number_float()) {
        const double v = value.get<double>();
        if (!std::isfinite(v)) {
            out += "null";
            return;
        }
        const std::size_t start = out.size();
        append_number(out, v);
        // A whole number stays a floating-point one to a reader (as dump() writes it: 48000.0).
        if (out.find_first_of(".e", start) == std::string::npos) out += ".0";
        return;
    }
    if (!value.is_structured()) {
        out += value.dump();  // strings (escaped), integers, booleans, null
        return;
    }
    const bool object = value.is_object();
    if (value.empty()) {
        out += object ? "{}" : "[]";
        return;
    }
    out += object ? '{' : '[';
    bool first = true;
    for (auto it = value.begin(); it != value.end(); ++it) {
        if (!first) out += ',';
        first = false;
        if (indent >= 0) {
            out += '\n';
            out.append(static_cast<std::size_t>((depth + 1) * indent), ' ');
        }
        if (object) {
            out += nlohmann::ordered_json(it.key()).dump();
            out += indent >= 0 ? ": " : ":";
        }
        append_json(out, *it, indent, depth + 1);
    }
    if (indent >= 0) {
        out += '\n';
        out.append(static_cast<std::size_t>(depth * indent), ' ');
    }
    out += object ? '}' : ']';
}

}  // namespace

std::string json_text(const nlohmann::ordered_json& value, int indent) {
    std::string out;
    append_json(out, value, indent, 0);
    return out;
}

}  // namespace fretbuzz
