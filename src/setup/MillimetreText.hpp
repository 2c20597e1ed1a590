#pragma once
// A length in metres as the set-up's messages and advice quote it: "1.25 mm" (three digits),
// and in a workshop's units (the instrument file's: mm, 64ths of an inch or thousandths),
// mm beside.
#include <cmath>
#include <cstdio>
#include <string>

#include "fretbuzz/input/Instrument.hpp"

namespace fretbuzz {

inline constexpr double kInch = 0.0254;

inline std::string mm_text(double metres) {
    char text[48];
    std::snprintf(text, sizeof text, "%.3g mm", metres * 1e3);
    return text;
}

// "2.40 mm", "6.0/64 in (2.40 mm)", "0.094 in (2.40 mm)"; with `change`, signed ("+0.60 mm").
inline std::string shop_text(double metres, ShopUnits units, bool change = false) {
    char mm[48], in[48];
    std::snprintf(mm, sizeof mm, change ? "%+.2f mm" : "%.2f mm", metres * 1e3);
    if (units == ShopUnits::mm) return mm;
    if (units == ShopUnits::sixty_fourths)
        std::snprintf(in, sizeof in, change ? "%+.1f/64 in" : "%.1f/64 in", metres / kInch * 64.0);
    else
        std::snprintf(in, sizeof in, change ? "%+.3f in" : "%.3f in", metres / kInch);
    return std::string(in) + " (" + mm + ")";
}

// Small lengths (relief, fret heights) in a workshop that measures in inches: thousandths
// (feeler gauges), whatever the action is given in.
inline ShopUnits fine_units(ShopUnits units) { return units == ShopUnits::mm ? ShopUnits::mm : ShopUnits::thousandths; }

inline const char* units_name(ShopUnits units) {
    return units == ShopUnits::mm ? "mm" : units == ShopUnits::sixty_fourths ? "64ths" : "thousandths";
}

}  // namespace fretbuzz
