#include <hairvox/core/error.h>
#include <hairvox/shots/frame_pattern.h>

#include <cstdio>
#include <cstdlib>

namespace hairvox::shots {

namespace {

/// The frame as printf's "%0<width>d" writes it (width 0: "%d").
std::string padded(int frame, int width) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%0*d", width, frame);
    return buffer;
}

/// Calls text(literal) and number(width) for each piece of the pattern.
template <typename Text, typename Number>
void scan(std::string_view pattern, std::string_view what, const Text& text, const Number& number) {
    for (std::size_t i = 0; i < pattern.size();) {
        if (pattern[i] == '#') {
            std::size_t j = i;
            while (j < pattern.size() && pattern[j] == '#')
                ++j;
            if (j - i > 9)
                throw InputError(strCat(what, ": '", pattern, "': ", j - i,
                                        " '#' in a row; a frame number is padded to 9 digits "
                                        "at most"));
            number(static_cast<int>(j - i), true);
            i = j;
        } else if (pattern[i] == '%') {
            if (i + 1 < pattern.size() && pattern[i + 1] == '%') {
                text('%', true);
                i += 2;
            } else if (i + 1 < pattern.size() && pattern[i + 1] == 'd') {
                number(0, false);
                i += 2;
            } else if (i + 3 < pattern.size() && pattern[i + 1] == '0' && pattern[i + 2] >= '1' &&
                       pattern[i + 2] <= '9' && pattern[i + 3] == 'd') {
                number(pattern[i + 2] - '0', false);
                i += 4;
            } else {
                throw InputError(strCat(what, ": '", pattern, "': a '%' at character ", i + 1,
                                        " starts no frame number (%d, %04d, or %% for a '%'; or "
                                        "#### as Nuke and Houdini write it)"));
            }
        } else {
            text(pattern[i], false);
            ++i;
        }
    }
}

} // namespace

bool hasFramePattern(std::string_view pattern) {
    bool found = false;
    try {
        scan(
            pattern, "", [](char, bool) {}, [&](int, bool) { found = true; });
    } catch (const InputError&) {
        return false;
    }
    return found;
}

std::string expandFramePattern(std::string_view pattern, int frame, std::string_view what) {
    std::string out;
    scan(
        pattern, what, [&](char c, bool) { out += c; },
        [&](int width, bool hashes) { out += padded(frame, hashes && width == 1 ? 0 : width); });
    return out;
}

std::string printfFramePattern(std::string_view pattern, std::string_view what) {
    std::string out;
    scan(
        pattern, what,
        [&](char c, bool escaped) {
            if (escaped)
                out += "%%";
            else
                out += c;
        },
        [&](int width, bool hashes) {
            const int w = hashes && width == 1 ? 0 : width;
            out += w == 0 ? std::string("%d") : strCat("%0", w, "d");
        });
    return out;
}

} // namespace hairvox::shots
