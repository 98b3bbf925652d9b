// hairvox CLI: small helpers for human-readable reports.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace hairvox::cli {

/// 1234567 -> "1,234,567".
inline std::string thousands(std::uint64_t n) {
    std::string digits = std::to_string(n), out;
    for (std::size_t i = 0; i < digits.size(); ++i) {
        if (i > 0 && (digits.size() - i) % 3 == 0)
            out += ',';
        out += digits[i];
    }
    return out;
}

inline std::string join(const std::vector<std::string>& parts, const std::string& separator) {
    std::string out;
    for (const std::string& p : parts)
        out += (out.empty() ? "" : separator) + p;
    return out;
}

} // namespace hairvox::cli
