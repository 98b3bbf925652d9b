#include <hairvox/core/error.h>
#include <hairvox/pipeline/groom_attributes.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numeric>

namespace hairvox {

namespace {

/// Calls f(strand, point within the strand, global point index) for every point.
template <typename F>
void forEachPoint(const Groom& groom, const F& f) {
    for (std::size_t s = 0; s < groom.strandCount(); ++s)
        for (std::size_t i = groom.strandStart[s]; i < groom.strandStart[s + 1]; ++i)
            f(s, i - groom.strandStart[s], i);
}

/// The largest D_i a scene may give: FiberScale's range for D.
constexpr float kMaxDiameter = 1000.0f;

} // namespace

std::string resolveThickness(Groom& groom, GroomThickness rule, const FiberScale& scale,
                             const std::string& source, std::vector<std::string>& warnings) {
    if (groom.thickness.empty())
        return "";
    if (rule == GroomThickness::Auto)
        rule = std::filesystem::path(source).extension() == ".tfx" ? GroomThickness::Scale
                                                                   : GroomThickness::Diameter;
    if (rule == GroomThickness::Ignore) {
        groom.thickness.clear();
        return strCat("per-point thickness ignored (groom.thickness = \"ignore\"): every fiber is ",
                      scale.diameter, " wide");
    }
    const float unit = rule == GroomThickness::Scale ? scale.diameter : 1.0f;
    float lo = INFINITY, hi = 0;
    forEachPoint(groom, [&](std::size_t s, std::size_t k, std::size_t i) {
        const float t = groom.thickness[i];
        const float d = t * unit;
        if (!(t >= 0) || !(d <= kMaxDiameter))
            throw InputError(strCat(source, ": strand ", s, ", point ", k, ": thickness ", t,
                                    " gives a fiber diameter of ", d,
                                    "; expected a finite diameter in [0, ", kMaxDiameter, "]"));
        groom.thickness[i] = d;
        lo = std::min(lo, d);
        hi = std::max(hi, d);
    });
    if (!(hi > 0))
        throw InputError(strCat(source, ": every point's thickness is 0, so no fiber would be "
                                        "seen; set groom.thickness to \"ignore\" to draw every "
                                        "fiber fiber.diameter wide"));
    const float ratioLo = lo / scale.diameter, ratioHi = hi / scale.diameter;
    if (ratioHi > 100.0f || ratioHi < 0.01f)
        warnings.push_back(strCat(source, ": per-point fiber diameters reach ", ratioHi,
                                  " x fiber.diameter (", scale.diameter,
                                  "): check the units (groom.thickness \"", toString(rule),
                                  "\"; \"diameter\" reads scene units, \"scale\" multiplies "
                                  "fiber.diameter)"));
    return strCat("per-point diameter (groom.thickness \"", toString(rule), "\"): ", lo, " to ", hi,
                  ", ", ratioLo, " to ", ratioHi, " x fiber.diameter");
}

namespace {

/// Splits the colours into at most `maxTypes` boxes: the box with the widest
/// channel range is cut at the middle of that range, until there are enough
/// boxes or every box holds one colour. Greedy on the largest channel error
/// (a box's colours are within half its widest range of its mean). Returns the
/// box of each colour.
std::vector<std::uint8_t> splitWidest(const std::vector<Rgb>& colors, std::size_t maxTypes) {
    std::vector<std::uint32_t> order(colors.size());
    std::iota(order.begin(), order.end(), 0u);
    struct Box {
        std::size_t begin, end;
        Rgb lo, hi;
        float extent() const { return (hi - lo).maxComponent(); }
    };
    const auto makeBox = [&](std::size_t begin, std::size_t end) {
        Box box{begin, end, Rgb(INFINITY), Rgb(-INFINITY)};
        for (std::size_t i = begin; i < end; ++i) {
            box.lo = min(box.lo, colors[order[i]]);
            box.hi = max(box.hi, colors[order[i]]);
        }
        return box;
    };
    std::vector<Box> boxes{makeBox(0, order.size())};
    while (boxes.size() < maxTypes) {
        const auto widest =
            std::max_element(boxes.begin(), boxes.end(),
                             [](const Box& a, const Box& b) { return a.extent() < b.extent(); });
        if (!(widest->extent() > 0))
            break; // every box holds one colour
        const Rgb range = widest->hi - widest->lo;
        const int axis =
            range.r >= range.g ? (range.r >= range.b ? 0 : 2) : (range.g >= range.b ? 1 : 2);
        const float middle = 0.5f * (widest->lo[axis] + widest->hi[axis]);
        const auto first = order.begin() + std::ptrdiff_t(widest->begin);
        const auto last = order.begin() + std::ptrdiff_t(widest->end);
        // Both sides are non-empty: lo < middle ≤ hi up to rounding, and
        // stable_partition keeps the order a function of the input alone.
        auto cut = std::stable_partition(first, last,
                                         [&](std::uint32_t i) { return colors[i][axis] < middle; });
        if (cut == first || cut == last)
            cut = first + (last - first) / 2;
        const std::size_t begin = widest->begin, mid = std::size_t(cut - order.begin()),
                          end = widest->end;
        *widest = makeBox(begin, mid);
        boxes.push_back(makeBox(mid, end));
    }
    std::vector<std::uint8_t> type(colors.size());
    for (std::size_t b = 0; b < boxes.size(); ++b)
        for (std::size_t i = boxes[b].begin; i < boxes[b].end; ++i)
            type[order[i]] = static_cast<std::uint8_t>(b);
    return type;
}

} // namespace

FiberPalette resolveColors(Groom& groom, GroomColor rule, const FiberParams& base,
                           const std::string& source, std::vector<std::string>& warnings) {
    FiberPalette palette;
    groom.fiberType.clear();
    if (rule == GroomColor::Ignore || groom.color.empty()) {
        palette.fibers.push_back(base);
        return palette;
    }
    forEachPoint(groom, [&](std::size_t s, std::size_t k, std::size_t i) {
        const Rgb& c = groom.color[i];
        if (!(c.r >= 0 && c.g >= 0 && c.b >= 0 && std::isfinite(c.r + c.g + c.b)))
            throw InputError(strCat(source, ": strand ", s, ", point ", k, ": colour ", c,
                                    " is negative or not finite"));
    });
    // A segment's colour, stored at its first point; a strand's last point
    // repeats its last segment's.
    const std::size_t n = groom.pointCount();
    std::vector<Rgb> segment(n);
    for (std::size_t s = 0; s < groom.strandCount(); ++s) {
        const std::size_t begin = groom.strandStart[s], end = groom.strandStart[s + 1];
        for (std::size_t i = begin; i + 1 < end; ++i)
            segment[i] = min(0.5f * (groom.color[i] + groom.color[i + 1]), Rgb(1.0f));
        segment[end - 1] = segment[end - 2];
    }
    // Up to kMaxFiberTypes distinct colours are kept exactly.
    std::vector<Rgb> distinct;
    std::vector<std::uint8_t> type(n);
    for (std::size_t i = 0; i < n && distinct.size() <= kMaxFiberTypes; ++i) {
        const auto it = std::find(distinct.begin(), distinct.end(), segment[i]);
        type[i] = static_cast<std::uint8_t>(it - distinct.begin());
        if (it == distinct.end())
            distinct.push_back(segment[i]);
    }
    if (distinct.size() <= kMaxFiberTypes) {
        palette.colors = distinct;
    } else {
        type = splitWidest(segment, kMaxFiberTypes);
        std::size_t types = 0;
        for (std::uint8_t t : type)
            types = std::max<std::size_t>(types, t + 1u);
        // Each type's colour: the mean of its segments'.
        std::vector<Rgbd> sum(types);
        std::vector<double> count(types, 0.0);
        for (std::size_t i = 0; i < n; ++i) {
            sum[type[i]] += Rgbd(segment[i]);
            count[type[i]] += 1;
        }
        for (std::size_t t = 0; t < types; ++t)
            palette.colors.push_back(Rgb(sum[t] / count[t]));
        for (std::size_t i = 0; i < n; ++i)
            for (int c = 0; c < 3; ++c)
                palette.maxColorError = std::max(
                    palette.maxColorError, std::abs(segment[i][c] - palette.colors[type[i]][c]));
        if (palette.maxColorError > 0.02f)
            warnings.push_back(strCat(source, ": more than ", kMaxFiberTypes,
                                      " distinct fiber colours, quantised into ", types,
                                      " fiber types; the largest change of a colour channel is ",
                                      palette.maxColorError));
    }
    for (const Rgb& c : palette.colors) {
        FiberParams fiber = base;
        fiber.sigma_a = FiberParams::sigmaFromColor(c);
        palette.fibers.push_back(fiber);
    }
    groom.fiberType = std::move(type);
    return palette;
}

} // namespace hairvox
