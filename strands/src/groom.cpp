#include <hairvox/core/error.h>
#include <hairvox/core/hash.h>
#include <hairvox/strands/groom.h>

#include <algorithm>
#include <limits>

namespace hairvox {

void Groom::addStrand(std::span<const Vec3f> strandPoints) {
    if (strandStart.empty())
        strandStart.push_back(0);
    points.insert(points.end(), strandPoints.begin(), strandPoints.end());
    strandStart.push_back(static_cast<std::uint32_t>(points.size()));
}

Bounds3f Groom::bounds() const {
    Bounds3f b;
    for (const Vec3f& p : points)
        b.extend(p);
    return b;
}

double Groom::totalLength() const {
    double total = 0;
    for (std::size_t s = 0; s < strandCount(); ++s) {
        const auto pts = strand(s);
        for (std::size_t k = 1; k < pts.size(); ++k)
            total += static_cast<double>(glm::distance(pts[k - 1], pts[k]));
    }
    return total;
}

void strandTangents(std::span<const Vec3f> points, std::span<Vec3f> tangents) {
    Vec3f previous(0.0f);
    for (std::size_t k = 0; k < points.size(); ++k) {
        const Vec3f next =
            k + 1 < points.size() ? normalizeOr(points[k + 1] - points[k], Vec3f(0.0f)) : Vec3f(0.0f);
        tangents[k] = normalizeOr(previous + next, normalizeOr(next, previous));
        previous = next;
    }
}

GroomStats computeStats(const Groom& groom) {
    GroomStats st;
    st.strands = groom.strandCount();
    st.points = groom.pointCount();
    st.segments = groom.empty() ? 0 : groom.segmentCount();
    st.bounds = groom.bounds();
    double minLen = std::numeric_limits<double>::infinity(), maxLen = 0;
    for (std::size_t s = 0; s < groom.strandCount(); ++s) {
        const auto pts = groom.strand(s);
        for (std::size_t k = 1; k < pts.size(); ++k) {
            const auto len = static_cast<double>(glm::distance(pts[k - 1], pts[k]));
            st.totalLength += len;
            minLen = std::min(minLen, len);
            maxLen = std::max(maxLen, len);
        }
    }
    if (st.segments > 0) {
        st.meanSegmentLength = st.totalLength / static_cast<double>(st.segments);
        st.minSegmentLength = minLen;
        st.maxSegmentLength = maxLen;
    }
    return st;
}

std::uint64_t contentHash(const Groom& groom) {
    Hasher h;
    h.values(std::span<const Vec3f>(groom.points));
    h.values(std::span<const std::uint32_t>(groom.strandStart));
    return h.digest();
}

std::ostream& operator<<(std::ostream& os, const Groom& groom) {
    return os << "Groom(strands=" << groom.strandCount() << ", points=" << groom.pointCount()
              << ", bounds=" << groom.bounds() << ")";
}

namespace {

/// Segments at most this long, relative to the groom's extent, count as zero
/// length: their tangent would be dominated by rounding.
constexpr float kZeroSegmentRelative = 1e-7f;

template <typename T>
void checkAttributeSize(const std::vector<T>& attribute, std::size_t points, const char* name,
                        const std::string& source) {
    if (!attribute.empty() && attribute.size() != points)
        throw InputError(strCat(source, ": ", name, " has ", attribute.size(),
                                " values for ", points, " points"));
}

template <typename T>
void keepSelected(std::vector<T>& attribute, const std::vector<bool>& keep) {
    if (attribute.empty())
        return;
    std::size_t out = 0;
    for (std::size_t i = 0; i < attribute.size(); ++i)
        if (keep[i])
            attribute[out++] = attribute[i];
    attribute.resize(out);
}

} // namespace

SanitizeReport sanitizeGroom(Groom& groom, const std::string& source) {
    SanitizeReport report;
    const std::size_t n = groom.points.size();
    if (groom.strandStart.empty()) {
        if (n != 0)
            throw InputError(strCat(source, ": ", n, " points but no strands"));
        return report;
    }
    if (groom.strandStart.front() != 0 || groom.strandStart.back() != n ||
        !std::is_sorted(groom.strandStart.begin(), groom.strandStart.end()))
        throw InputError(strCat(source, ": strand offsets do not partition the ", n, " points"));
    checkAttributeSize(groom.thickness, n, "thickness", source);
    checkAttributeSize(groom.transparency, n, "transparency", source);
    checkAttributeSize(groom.color, n, "color", source);
    checkAttributeSize(groom.fiberType, n, "fiber type", source);

    for (std::size_t s = 0; s < groom.strandCount(); ++s) {
        const auto pts = groom.strand(s);
        if (pts.size() < 2)
            throw InputError(strCat(source, ": strand ", s, " has ", pts.size(),
                                    " point(s); a strand needs at least 2"));
        for (std::size_t k = 0; k < pts.size(); ++k)
            if (!isFinite(pts[k]))
                throw InputError(strCat(source, ": strand ", s, ", point ", k,
                                        " has a non-finite coordinate ", pts[k]));
    }

    const Vec3f extent = groom.bounds().extent();
    const float minLength = kZeroSegmentRelative * std::max({extent.x, extent.y, extent.z});

    // Mark points that repeat their predecessor; drop strands left with one point.
    std::vector<bool> keep(n, true);
    std::vector<std::uint32_t> newStart{0};
    std::uint32_t kept = 0;
    for (std::size_t s = 0; s < groom.strandCount(); ++s) {
        const std::uint32_t begin = groom.strandStart[s], end = groom.strandStart[s + 1];
        std::uint32_t last = begin, strandKept = 1;
        for (std::uint32_t i = begin + 1; i < end; ++i) {
            if (glm::distance(groom.points[i], groom.points[last]) <= minLength) {
                keep[i] = false;
                ++report.droppedSegments;
            } else {
                last = i;
                ++strandKept;
            }
        }
        if (strandKept < 2) {
            keep[begin] = false;
            ++report.droppedStrands;
            continue;
        }
        kept += strandKept;
        newStart.push_back(kept);
    }
    if (report.droppedSegments == 0)
        return report;

    keepSelected(groom.points, keep);
    keepSelected(groom.thickness, keep);
    keepSelected(groom.transparency, keep);
    keepSelected(groom.color, keep);
    keepSelected(groom.fiberType, keep);
    groom.strandStart = newStart.size() > 1 ? std::move(newStart) : std::vector<std::uint32_t>{};
    return report;
}

std::size_t fiberTypeCount(const Groom& groom) {
    std::size_t types = 1;
    for (std::uint8_t t : groom.fiberType)
        types = std::max<std::size_t>(types, t + 1u);
    return types;
}

float maxRibbonWidth(const Groom& groom, const FiberScale& scale) {
    if (groom.thickness.empty())
        return scale.ribbonWidth();
    return *std::max_element(groom.thickness.begin(), groom.thickness.end()) *
           scale.densityMultiplier;
}

} // namespace hairvox
