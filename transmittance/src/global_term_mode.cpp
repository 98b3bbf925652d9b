#include <hairvox/transmittance/global_term_mode.h>

namespace hairvox {

const char* toString(GlobalTermMode mode) {
    switch (mode) {
    case GlobalTermMode::Exact: return "exact";
    case GlobalTermMode::Grid: return "grid";
    case GlobalTermMode::Approx: return "approx";
    }
    return "unknown";
}

std::optional<GlobalTermMode> parseGlobalTermMode(std::string_view name) {
    for (GlobalTermMode m : {GlobalTermMode::Exact, GlobalTermMode::Grid, GlobalTermMode::Approx})
        if (name == toString(m))
            return m;
    return std::nullopt;
}

} // namespace hairvox
