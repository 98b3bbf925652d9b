#include <hairvox/core/error.h>
#include <hairvox/geometry/ray_scene.h>

#include <embree3/rtcore.h>
#include <glm/common.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <mutex>
#include <stdexcept>

namespace hairvox {

namespace {

/// Embree has no exceptions: check the device's error state after each call
/// that can fail and turn it into one.
void checkEmbree(RTCDevice device, const char* what) {
    const RTCError error = rtcGetDeviceError(device);
    if (error != RTC_ERROR_NONE)
        throw std::runtime_error(strCat("Embree error ", static_cast<int>(error), " in ", what));
}

struct RawHit {
    float t;
    std::uint32_t primID;
};

/// The intersect context handed to the filter; Embree passes it back as its
/// first member, so the filter can find the hit list.
struct CollectContext {
    RTCIntersectContext context;
    std::vector<RawHit>* hits;
};

/// Records every candidate hit and rejects it, so traversal visits all hits.
void collectHits(const RTCFilterFunctionNArguments* args) {
    auto* collect = reinterpret_cast<CollectContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0)
            continue;
        collect->hits->push_back(
            {RTCRayN_tfar(args->ray, args->N, i), RTCHitN_primID(args->hit, args->N, i)});
        args->valid[i] = 0;
    }
}

float distanceToSegment(const Vec3f& p, const Vec3f& a, const Vec3f& b) {
    const Vec3f ab = b - a;
    const float len2 = glm::dot(ab, ab);
    const float t = len2 > 0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
    return glm::distance(p, a + t * ab);
}

} // namespace

namespace {

/// Segments binned by the cells of a uniform grid that their bounds (padded by
/// the search radius) overlap: the nearest-segment search for points whose
/// strand is unknown, since Embree 3 has no point queries on curves.
class SegmentGrid {
public:
    template <typename SegmentEnds>
    SegmentGrid(std::size_t segmentCount, float cellSize, float pad, SegmentEnds&& ends)
        : invCell_(1.0f / cellSize) {
        for (std::size_t s = 0; s < segmentCount; ++s) {
            const auto [a, b] = ends(s);
            const glm::ivec3 lo = cell(glm::min(a, b) - pad), hi = cell(glm::max(a, b) + pad);
            for (int x = lo.x; x <= hi.x; ++x)
                for (int y = lo.y; y <= hi.y; ++y)
                    for (int z = lo.z; z <= hi.z; ++z)
                        entries_.push_back({key({x, y, z}), static_cast<std::uint32_t>(s)});
        }
        std::sort(entries_.begin(), entries_.end());
    }

    /// Segments whose padded bounds contain p's cell.
    template <typename F>
    void forEachNear(const Vec3f& p, F&& f) const {
        const std::uint64_t k = key(cell(p));
        auto it = std::lower_bound(entries_.begin(), entries_.end(), Entry{k, 0});
        for (; it != entries_.end() && it->key == k; ++it)
            f(it->segment);
    }

private:
    struct Entry {
        std::uint64_t key;
        std::uint32_t segment;
        auto operator<=>(const Entry&) const = default;
    };
    glm::ivec3 cell(const Vec3f& p) const { return glm::ivec3(glm::floor(p * invCell_)); }
    static std::uint64_t key(const glm::ivec3& c) {
        const auto part = [](int v) {
            return static_cast<std::uint64_t>(v + (1 << 20)) & 0x1fffffu;
        };
        return part(c.x) | (part(c.y) << 21) | (part(c.z) << 42);
    }

    float invCell_;
    std::vector<Entry> entries_;
};

} // namespace

struct RayScene::Impl {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    std::vector<float> vertices;             ///< x, y, z, radius per point (+1 padding vertex)
    std::vector<std::uint32_t> segmentStart; ///< first vertex of each segment (Embree index buffer)
    std::vector<std::uint32_t> segmentStrand;
    std::vector<float> segmentArcStart; ///< arc length from the root to the segment start
    std::vector<Vec3f> segmentTangent;
    std::vector<std::uint32_t> strandFirstSegment; ///< per strand, plus one past the end
    mutable std::once_flag gridOnce;
    mutable std::unique_ptr<SegmentGrid> grid;

    Vec3f vertex(std::uint32_t i) const {
        return {vertices[4 * i], vertices[4 * i + 1], vertices[4 * i + 2]};
    }
    std::pair<Vec3f, Vec3f> segmentEnds(std::size_t s) const {
        return {vertex(segmentStart[s]), vertex(segmentStart[s] + 1)};
    }
    /// Arc length along the strand of the centreline point nearest to p on segment s.
    float arcLengthAt(std::uint32_t s, const Vec3f& p) const {
        const auto [a, b] = segmentEnds(s);
        const float len = glm::distance(a, b);
        return segmentArcStart[s] + std::clamp(glm::dot(p - a, segmentTangent[s]), 0.0f, len);
    }

    ~Impl() {
        if (scene)
            rtcReleaseScene(scene);
        if (device)
            rtcReleaseDevice(device);
    }
};

RayScene::RayScene(const Groom& groom, const FiberScale& scale)
    : impl_(std::make_unique<Impl>())
    , width_(scale.ribbonWidth())
    , locateDistance_(std::max(1.0f, scale.densityMultiplier) * scale.diameter) {
    Impl& m = *impl_;
    const float radius = 0.5f * width_;
    m.vertices.reserve(4 * (groom.pointCount() + 1));
    for (const Vec3f& p : groom.points)
        m.vertices.insert(m.vertices.end(), {p.x, p.y, p.z, radius});
    m.vertices.insert(m.vertices.end(), {0.0f, 0.0f, 0.0f, 0.0f}); // Embree reads 16 bytes past
    for (std::size_t s = 0; s < groom.strandCount(); ++s) {
        m.strandFirstSegment.push_back(static_cast<std::uint32_t>(m.segmentStart.size()));
        float arc = 0;
        for (std::uint32_t i = groom.strandStart[s]; i + 1 < groom.strandStart[s + 1]; ++i) {
            m.segmentStart.push_back(i);
            m.segmentStrand.push_back(static_cast<std::uint32_t>(s));
            m.segmentArcStart.push_back(arc);
            m.segmentTangent.push_back(
                normalizeOr(groom.points[i + 1] - groom.points[i], Vec3f(0.0f, 1.0f, 0.0f)));
            arc += glm::distance(groom.points[i], groom.points[i + 1]);
        }
    }
    m.strandFirstSegment.push_back(static_cast<std::uint32_t>(m.segmentStart.size()));

    m.device = rtcNewDevice(nullptr);
    if (!m.device)
        throw std::runtime_error("cannot create an Embree device");
    m.scene = rtcNewScene(m.device);
    rtcSetSceneFlags(m.scene, RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION | RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(m.scene, RTC_BUILD_QUALITY_HIGH);
    if (!m.segmentStart.empty()) {
        RTCGeometry geometry = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_FLAT_LINEAR_CURVE);
        rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                   m.vertices.data(), 0, 4 * sizeof(float), groom.pointCount());
        rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT,
                                   m.segmentStart.data(), 0, sizeof(std::uint32_t),
                                   m.segmentStart.size());
        rtcCommitGeometry(geometry);
        rtcAttachGeometry(m.scene, geometry);
        rtcReleaseGeometry(geometry);
    }
    rtcCommitScene(m.scene);
    checkEmbree(m.device, "building the strand scene");
}

RayScene::~RayScene() = default;

void RayScene::crossings(const Vec3f& origin, const Vec3f& dir, float tMax,
                         std::vector<FiberCrossing>& out) const {
    const Impl& m = *impl_;
    out.clear();
    if (m.segmentStart.empty())
        return;
    thread_local std::vector<RawHit> hits;
    hits.clear();
    CollectContext collect{};
    rtcInitIntersectContext(&collect.context);
    collect.context.filter = collectHits;
    collect.hits = &hits;

    RTCRayHit rayHit{};
    rayHit.ray.org_x = origin.x;
    rayHit.ray.org_y = origin.y;
    rayHit.ray.org_z = origin.z;
    rayHit.ray.dir_x = dir.x;
    rayHit.ray.dir_y = dir.y;
    rayHit.ray.dir_z = dir.z;
    rayHit.ray.tnear = 0.0f;
    rayHit.ray.tfar = std::min(tMax, std::numeric_limits<float>::max());
    rayHit.ray.mask = ~0u;
    rayHit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(m.scene, &collect.context, &rayHit);

    // The same primitive can be reported more than once: keep its first hit.
    std::sort(hits.begin(), hits.end(), [](const RawHit& a, const RawHit& b) {
        return a.primID != b.primID ? a.primID < b.primID : a.t < b.t;
    });
    hits.erase(std::unique(hits.begin(), hits.end(),
                           [](const RawHit& a, const RawHit& b) { return a.primID == b.primID; }),
               hits.end());
    std::sort(hits.begin(), hits.end(), [](const RawHit& a, const RawHit& b) {
        return a.t != b.t ? a.t < b.t : a.primID < b.primID;
    });
    // A ray through the joint of two consecutive segments of one strand hits
    // both ribbons within about a ribbon width: one crossing.
    for (const RawHit& h : hits) {
        const std::uint32_t strand = m.segmentStrand[h.primID];
        const bool jointDuplicate = std::any_of(
            out.rbegin(),
            std::find_if(out.rbegin(), out.rend(),
                         [&](const FiberCrossing& c) { return h.t - c.t > 2 * width_; }),
            [&](const FiberCrossing& c) {
                return c.strand == strand &&
                       (c.segment + 1 == h.primID || h.primID + 1 == c.segment);
            });
        if (!jointDuplicate)
            out.push_back({h.t, strand, h.primID, m.arcLengthAt(h.primID, origin + h.t * dir),
                           m.segmentTangent[h.primID]});
    }
}

std::optional<FiberPoint> RayScene::locate(const Vec3f& p, std::uint32_t strandHint) const {
    const Impl& m = *impl_;
    std::optional<FiberPoint> best;
    float bestDistance = locateDistance_;
    const auto consider = [&](std::uint32_t s) {
        const auto [a, b] = m.segmentEnds(s);
        const float d = distanceToSegment(p, a, b);
        if (d <= bestDistance) {
            bestDistance = d;
            best = FiberPoint{m.segmentStrand[s], s, m.arcLengthAt(s, p)};
        }
    };
    if (strandHint < m.strandFirstSegment.size() - 1) {
        for (std::uint32_t s = m.strandFirstSegment[strandHint];
             s < m.strandFirstSegment[strandHint + 1]; ++s)
            consider(s);
        return best;
    }
    if (m.segmentStart.empty())
        return best;
    std::call_once(m.gridOnce, [&] {
        // Cells about one segment long: a segment spans few cells, a cell holds few segments.
        double length = 0;
        for (std::size_t s = 0; s < m.segmentStart.size(); ++s) {
            const auto [a, b] = m.segmentEnds(s);
            length += double(glm::distance(a, b));
        }
        const float cell = std::max(static_cast<float>(length / double(m.segmentStart.size())),
                                    4.0f * locateDistance_);
        m.grid = std::make_unique<SegmentGrid>(m.segmentStart.size(), cell, locateDistance_,
                                               [&](std::size_t s) { return m.segmentEnds(s); });
    });
    m.grid->forEachNear(p, consider);
    return best;
}

} // namespace hairvox
