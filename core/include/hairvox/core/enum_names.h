// hairvox core: the names of an enum's values, written once.
//
// Every enum that appears in a file or on the command line (global-term
// modes, groom styles, shading rates, tone maps, ...) declares one table of
// its values and their names; printing, parsing, the scene reader's list of
// valid choices and the CLI's option checks all read that table, so a name
// cannot be spelt two ways in two places.
//
//   inline constexpr EnumNames<ShadingRate, 2> kShadingRateNames{{{
//       {ShadingRate::Fragment, "fragment"}, {ShadingRate::Vertex, "vertex"}}}};
//   kShadingRateNames.name(ShadingRate::Vertex)   // "vertex"
//   kShadingRateNames.parse("fragment")           // ShadingRate::Fragment
//   kShadingRateNames.names()                     // {"fragment", "vertex"}
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace hairvox {

template <typename E>
struct EnumName {
    E value;
    const char* name;
};

template <typename E, std::size_t N>
struct EnumNames {
    std::array<EnumName<E>, N> entries;

    /// The value's name ("unknown" for a value outside the table).
    constexpr const char* name(E value) const {
        for (const EnumName<E>& e : entries)
            if (e.value == value)
                return e.name;
        return "unknown";
    }
    /// The value of a name, exactly as written in the table.
    constexpr std::optional<E> parse(std::string_view text) const {
        for (const EnumName<E>& e : entries)
            if (text == e.name)
                return e.value;
        return std::nullopt;
    }
    /// Every name, in table order (for "expected one of ..." messages and CLI checks).
    std::vector<std::string> names() const {
        std::vector<std::string> out;
        for (const EnumName<E>& e : entries)
            out.emplace_back(e.name);
        return out;
    }
};

} // namespace hairvox
