// hairvox shots: a set of frame numbers, as a render wrangler writes it on a
// command line — "1-240", every other frame "1-240x2", one frame "7", and
// lists of those "1-10,20,30-40x5" (Nuke's and Deadline's frame-list syntax).
#pragma once

#include <cstddef>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace hairvox::shots {

/// Frame numbers a shot may have: [kMinFrame, kMaxFrame], and at most
/// kMaxFrames of them in one set.
inline constexpr int kMinFrame = -999999;
inline constexpr int kMaxFrame = 9999999;
inline constexpr std::size_t kMaxFrames = 1000000;

class FrameSet {
public:
    FrameSet() = default;
    /// The frames first..last (inclusive) every `step`.
    static FrameSet range(int first, int last, int step = 1);
    /// Parses "A", "A-B", "A-BxS" and comma-separated lists of them (spaces
    /// allowed around the commas). InputError naming `what` (e.g. "--frames")
    /// and the part that is wrong: a number outside [kMinFrame, kMaxFrame],
    /// B < A, a step < 1, more than kMaxFrames frames, an empty list.
    static FrameSet parse(std::string_view text, std::string_view what = "--frames");
    /// The frames as sorted unique numbers.
    static FrameSet of(std::vector<int> frames);

    const std::vector<int>& frames() const { return frames_; }
    std::size_t size() const { return frames_.size(); }
    bool empty() const { return frames_.empty(); }
    bool contains(int frame) const;
    int first() const { return frames_.front(); }
    int last() const { return frames_.back(); }

    /// The frames of this set that `other` also has.
    FrameSet intersect(const FrameSet& other) const;
    /// Consecutive pieces of at most `perChunk` frames each, in order.
    std::vector<FrameSet> chunks(std::size_t perChunk) const;
    /// The shortest text parse() reads back as this set: runs of equal
    /// steps as "A-B" or "A-BxS", single frames as "A" ("" when empty).
    std::string toString() const;

    bool operator==(const FrameSet&) const = default;

private:
    std::vector<int> frames_; ///< sorted, unique
};

std::ostream& operator<<(std::ostream& os, const FrameSet& frames);

} // namespace hairvox::shots
