// hairvox transmittance: how the dual-scattering global term is computed
// (docs/DESIGN.md §5). Every consumer (renderer, probe, benchmark) switches
// between the modes through this one setting.
#pragma once

#include <hairvox/core/enum_names.h>

#include <ostream>

namespace hairvox {

enum class GlobalTermMode {
    Exact,  ///< Embree ray casting against the real strands (the reference)
    Grid,   ///< ray march through the fiber grid with each voxel's own orientation
    Approx, ///< n from the grid, every crossed fiber sharing the shading point's orientation
};

inline constexpr EnumNames<GlobalTermMode, 3> kGlobalTermModeNames{{{
    {GlobalTermMode::Exact, "exact"},
    {GlobalTermMode::Grid, "grid"},
    {GlobalTermMode::Approx, "approx"},
}}};

inline const char* toString(GlobalTermMode mode) {
    return kGlobalTermModeNames.name(mode);
}
inline std::ostream& operator<<(std::ostream& os, GlobalTermMode mode) {
    return os << toString(mode);
}

} // namespace hairvox
