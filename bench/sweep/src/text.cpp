#include "text.h"

#include <hairvox/core/atomic_file.h>
#include <hairvox/core/error.h>

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <fstream>

namespace hairvox::bench {

std::string format(const char* fmt, ...) {
    char buf[128];
    va_list args;
    va_start(args, fmt);
    std::vsnprintf(buf, sizeof(buf), fmt, args);
    va_end(args);
    return buf;
}

std::string scaleText(double scale) {
    return format("%g", scale);
}

std::string seconds(double s) {
    return format(s < 10 ? "%.2f" : "%.1f", s);
}

double median(std::vector<double> v) {
    if (v.empty())
        return 0;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

void writeTextFile(const std::filesystem::path& path, const std::string& text) {
    writeFileAtomically(path, [&](const std::filesystem::path& tmp) {
        std::ofstream out(tmp, std::ios::trunc);
        out << text;
        if (!out)
            throw InputError(strCat(path.string(), ": cannot write"));
    });
}

} // namespace hairvox::bench
