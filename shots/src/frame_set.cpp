#include <hairvox/core/error.h>
#include <hairvox/shots/frame_set.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdint>

namespace hairvox::shots {

namespace {

std::string_view trim(std::string_view s) {
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front())))
        s.remove_prefix(1);
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back())))
        s.remove_suffix(1);
    return s;
}

} // namespace

FrameSet FrameSet::range(int first, int last, int step) {
    FrameSet set;
    for (std::int64_t f = first; f <= last; f += std::max(step, 1))
        set.frames_.push_back(static_cast<int>(f));
    return set;
}

FrameSet FrameSet::of(std::vector<int> frames) {
    std::sort(frames.begin(), frames.end());
    frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
    FrameSet set;
    set.frames_ = std::move(frames);
    return set;
}

FrameSet FrameSet::parse(std::string_view text, std::string_view what) {
    const auto fail = [&](std::string_view part, std::string_view problem) -> void {
        throw InputError(strCat(what, " ", text, ": '", part, "' ", problem,
                                " (frames are written A, A-B or A-BxSTEP, separated by commas; "
                                "each in [",
                                kMinFrame, ", ", kMaxFrame, "])"));
    };
    std::vector<int> frames;
    std::size_t begin = 0;
    if (trim(text).empty())
        fail(text, "names no frame");
    while (begin <= text.size()) {
        const std::size_t comma = std::min(text.find(',', begin), text.size());
        const std::string_view part = trim(text.substr(begin, comma - begin));
        begin = comma + 1;
        // A number, optionally negative, read whole.
        std::size_t at = 0;
        const auto number = [&](const char* name) {
            std::int64_t v = 0;
            const char* first = part.data() + at;
            const auto [end, ec] = std::from_chars(first, part.data() + part.size(), v);
            if (ec != std::errc() || end == first)
                fail(part, strCat("does not start its ", name, " with a whole number"));
            at = static_cast<std::size_t>(end - part.data());
            if (v < kMinFrame || v > kMaxFrame)
                fail(part, strCat("has a ", name, " outside the frame numbers"));
            return static_cast<int>(v);
        };
        if (part.empty())
            fail(part, "is empty");
        const int a = number("first frame");
        int b = a, step = 1;
        // "-" after the first number: a range (the first may itself be negative).
        if (at < part.size() && part[at] == '-') {
            ++at;
            b = number("last frame");
            if (b < a)
                fail(part, "ends before it starts");
            if (at < part.size() && (part[at] == 'x' || part[at] == 'X')) {
                ++at;
                step = number("step");
                if (step < 1)
                    fail(part, "has a step below 1");
            }
        }
        if (at != part.size())
            fail(part, "has trailing characters");
        const std::uint64_t count = (std::uint64_t(std::int64_t(b) - a) / std::uint64_t(step)) + 1;
        if (frames.size() + count > kMaxFrames)
            fail(part, strCat("makes more than ", kMaxFrames, " frames"));
        for (std::int64_t f = a; f <= b; f += step)
            frames.push_back(static_cast<int>(f));
    }
    return of(std::move(frames));
}

bool FrameSet::contains(int frame) const {
    return std::binary_search(frames_.begin(), frames_.end(), frame);
}

FrameSet FrameSet::intersect(const FrameSet& other) const {
    FrameSet set;
    std::set_intersection(frames_.begin(), frames_.end(), other.frames_.begin(),
                          other.frames_.end(), std::back_inserter(set.frames_));
    return set;
}

std::vector<FrameSet> FrameSet::chunks(std::size_t perChunk) const {
    std::vector<FrameSet> out;
    perChunk = std::max<std::size_t>(perChunk, 1);
    for (std::size_t i = 0; i < frames_.size(); i += perChunk) {
        FrameSet chunk;
        chunk.frames_.assign(
            frames_.begin() + static_cast<std::ptrdiff_t>(i),
            frames_.begin() + static_cast<std::ptrdiff_t>(std::min(i + perChunk, frames_.size())));
        out.push_back(std::move(chunk));
    }
    return out;
}

std::string FrameSet::toString() const {
    std::string out;
    for (std::size_t i = 0; i < frames_.size();) {
        // The longest run from i with one step (two frames make a run only
        // when consecutive: "1,5" reads better than "1-5x4").
        std::size_t j = i + 1;
        if (j < frames_.size()) {
            const std::int64_t step = std::int64_t(frames_[j]) - frames_[i];
            while (j + 1 < frames_.size() && std::int64_t(frames_[j + 1]) - frames_[j] == step)
                ++j;
            if (j - i == 1 && step != 1)
                j = i; // a pair with a gap: two single frames
        } else {
            j = i;
        }
        if (!out.empty())
            out += ',';
        if (j == i) {
            out += std::to_string(frames_[i]);
            i += 1;
            continue;
        }
        const std::int64_t step = std::int64_t(frames_[i + 1]) - frames_[i];
        out += strCat(frames_[i], "-", frames_[j]);
        if (step != 1)
            out += strCat("x", step);
        i = j + 1;
    }
    return out;
}

std::ostream& operator<<(std::ostream& os, const FrameSet& frames) {
    return os << "FrameSet(" << frames.toString() << ", " << frames.size() << " frames)";
}

} // namespace hairvox::shots
