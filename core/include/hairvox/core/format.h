// hairvox core: small formatting helpers for human-readable reports.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace hairvox {

/// 1234567 -> "1,234,567".
std::string thousands(std::uint64_t n);

/// Joins parts with a separator: join({"a", "b"}, ", ") -> "a, b".
std::string join(const std::vector<std::string>& parts, const std::string& separator);

} // namespace hairvox
