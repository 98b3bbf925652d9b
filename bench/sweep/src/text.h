// hairvox bench (private): number formatting and small statistics shared by
// the sweep's log, tables and jobs.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace hairvox::bench {

/// printf-style formatting of a short value (at most 127 characters).
[[gnu::format(printf, 1, 2)]] std::string format(const char* fmt, ...);

/// A voxel scale as written in labels: 1.4, 0.7, 2.
std::string scaleText(double scale);

/// Seconds with 2 decimals below 10 s, 1 above.
std::string seconds(double s);

double median(std::vector<double> v);

/// Writes a text file atomically; InputError naming it on failure.
void writeTextFile(const std::filesystem::path& path, const std::string& text);

} // namespace hairvox::bench
