#include "embree_util.h"

#include <hairvox/core/error.h>
#include <hairvox/geometry/ray_scene.h>

#include <embree3/rtcore.h>
#include <glm/common.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <limits>
#include <mutex>
#include <stdexcept>

namespace hairvox {

namespace {

struct RawHit {
    float t;
    std::uint32_t primID;
};

/// The intersect context of every query: Embree passes it to the filter
/// (RayScene::filterHits), which skips hits off the ribbons and the ray
/// origin's own fiber, and collects every hit when asked to.
struct FilterContext {
    RTCIntersectContext context;
    const RayScene* scene;
    const RayOrigin* from;           ///< null: a ray that does not leave a fiber
    std::vector<RawHit>* collect;    ///< non-null: record every hit and reject it
};

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

/// Embree primitives are pieces of the segments: a segment is cut into this
/// many equal pieces, so that the bounding boxes the BVH is built from hug
/// the oblique, thin ribbons — measured on the default scene's groom (620k
/// segments, rays from random points on the fibers): 1 piece 0.14, 2 0.25,
/// 4 0.38, 8 0.42 M rays/s on 2 threads, for a build of 0.5, 0.8, 1.2, 2.2 s.
constexpr std::uint32_t kPiecesPerSegment = 4;

struct RayScene::Impl {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    std::vector<Vec3f> points;               ///< the groom's points
    std::vector<Vec3f> pointTangent;         ///< strandTangents() of every point
    std::vector<std::uint32_t> segmentStart; ///< first point of each segment
    std::vector<std::uint32_t> segmentStrand;
    std::vector<float> segmentArcStart; ///< arc length from the root to the segment start
    std::vector<Vec3f> segmentTangent;  ///< the segment's direction
    std::vector<std::uint32_t> strandFirstSegment; ///< per strand, plus one past the end
    std::vector<float> pieceVertices;        ///< x, y, z, radius per piece end (+1 padding vertex)
    std::vector<std::uint32_t> pieceStart;   ///< first piece vertex of each piece (Embree index buffer)
    std::vector<std::uint32_t> pieceSegment; ///< the segment each piece (Embree primitive) belongs to
    mutable std::once_flag gridOnce;
    mutable std::unique_ptr<SegmentGrid> grid;

    std::pair<Vec3f, Vec3f> segmentEnds(std::size_t s) const {
        return {points[segmentStart[s]], points[segmentStart[s] + 1]};
    }
    /// Where along segment s the centreline point nearest to p is, in [0, 1].
    float segmentParameter(std::uint32_t s, const Vec3f& p) const {
        const auto [a, b] = segmentEnds(s);
        const float len = glm::distance(a, b);
        return len > 0 ? std::clamp(glm::dot(p - a, segmentTangent[s]) / len, 0.0f, 1.0f) : 0.0f;
    }
    /// Arc length along the strand of the centreline point nearest to p on segment s.
    float arcLengthAt(std::uint32_t s, const Vec3f& p) const {
        const auto [a, b] = segmentEnds(s);
        return segmentArcStart[s] + segmentParameter(s, p) * glm::distance(a, b);
    }
    /// Whether p, a hit on piece `piece`, lies off the ribbon: on an end cap
    /// (beyond the piece's ends along it) or on a piece of width 0. Embree's
    /// flat linear curves have round caps; the fibers here are butt-ended
    /// ribbons, as the rasterizer draws them and as the global term's
    /// cross-section λ·k·D·cos θ counts them (nothing end-on). A piece of
    /// width 0 (a tapered tip, D_i = 0) covers nothing, though Embree reports
    /// a ray exactly through its centreline.
    bool offRibbon(std::uint32_t piece, const Vec3f& p) const {
        const float* v = &pieceVertices[4 * std::size_t(pieceStart[piece])];
        if (v[3] == 0.0f && v[7] == 0.0f)
            return true;
        const Vec3f a(v[0], v[1], v[2]), b(v[4], v[5], v[6]);
        const Vec3f ab = b - a;
        const float along = glm::dot(p - a, ab);
        return along < 0.0f || along > glm::dot(ab, ab);
    }
    /// The shading tangent at the point of segment s nearest to p (shadingTangent()).
    Vec3f tangentAt(std::uint32_t s, const Vec3f& p) const {
        const std::uint32_t k = segmentStart[s];
        return shadingTangent(pointTangent[k], pointTangent[k + 1], segmentParameter(s, p),
                              segmentTangent[s]);
    }

    ~Impl() {
        if (scene)
            rtcReleaseScene(scene);
        if (device)
            rtcReleaseDevice(device);
    }
};

RayScene::RayScene(const Groom& groom, const FiberScale& scale,
                   std::shared_ptr<const SurfaceScene> surfaces)
    : impl_(std::make_unique<Impl>())
    , surfaces_(std::move(surfaces)) {
    Impl& m = *impl_;
    // The widest ribbon bounds the joint test in crossings() and locate()'s
    // search: max(D_i, k·D_i) at the widest point, k·D_i / (k·D) times the
    // scale's max(D, k·D) (exactly that without per-point diameters).
    width_ = maxRibbonWidth(groom, scale);
    locateDistance_ =
        std::max(1.0f, scale.densityMultiplier) * scale.diameter * (width_ / scale.ribbonWidth());
    m.points = groom.points;
    m.pointTangent.resize(groom.pointCount());
    m.pieceVertices.reserve(4 * (kPiecesPerSegment * groom.pointCount() + 1));
    for (std::size_t s = 0; s < groom.strandCount(); ++s) {
        const std::uint32_t first = groom.strandStart[s], end = groom.strandStart[s + 1];
        strandTangents({groom.points.data() + first, end - first},
                       {m.pointTangent.data() + first, end - first});
        m.strandFirstSegment.push_back(static_cast<std::uint32_t>(m.segmentStart.size()));
        float arc = 0;
        for (std::uint32_t i = first; i + 1 < end; ++i) {
            const auto segment = static_cast<std::uint32_t>(m.segmentStart.size());
            m.segmentStart.push_back(i);
            m.segmentStrand.push_back(static_cast<std::uint32_t>(s));
            m.segmentArcStart.push_back(arc);
            m.segmentTangent.push_back(
                normalizeOr(groom.points[i + 1] - groom.points[i], Vec3f(0.0f, 1.0f, 0.0f)));
            arc += glm::distance(groom.points[i], groom.points[i + 1]);
            // The segment's pieces share their ends; consecutive pieces of a
            // strand are consecutive primitives (the joint test in crossings()).
            // The radius, half the ribbon width k·D_i, is linear along the
            // segment (strands/groom.h ribbonWidthAt()).
            const float r0 = 0.5f * ribbonWidthAt(groom, scale, i);
            const float r1 = 0.5f * ribbonWidthAt(groom, scale, i + 1);
            for (std::uint32_t j = 0; j < kPiecesPerSegment; ++j) {
                m.pieceStart.push_back(static_cast<std::uint32_t>(m.pieceVertices.size() / 4));
                m.pieceSegment.push_back(segment);
                const float f = float(j) / float(kPiecesPerSegment);
                const Vec3f p = groom.points[i] + f * (groom.points[i + 1] - groom.points[i]);
                m.pieceVertices.insert(m.pieceVertices.end(), {p.x, p.y, p.z, r0 + f * (r1 - r0)});
            }
        }
        if (end > first + 1) { // the strand's last point closes its last piece
            const Vec3f& p = groom.points[end - 1];
            m.pieceVertices.insert(m.pieceVertices.end(),
                                   {p.x, p.y, p.z, 0.5f * ribbonWidthAt(groom, scale, end - 1)});
        }
    }
    m.strandFirstSegment.push_back(static_cast<std::uint32_t>(m.segmentStart.size()));
    const std::size_t pieceVertexCount = m.pieceVertices.size() / 4;
    m.pieceVertices.insert(m.pieceVertices.end(), {0.0f, 0.0f, 0.0f, 0.0f}); // Embree reads past

    m.device = rtcNewDevice(nullptr);
    if (!m.device)
        throw std::runtime_error("cannot create an Embree device");
    m.scene = rtcNewScene(m.device);
    rtcSetSceneFlags(m.scene, RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION | RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(m.scene, RTC_BUILD_QUALITY_HIGH);
    if (!m.pieceStart.empty()) {
        RTCGeometry geometry = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_FLAT_LINEAR_CURVE);
        rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                   m.pieceVertices.data(), 0, 4 * sizeof(float), pieceVertexCount);
        rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT,
                                   m.pieceStart.data(), 0, sizeof(std::uint32_t),
                                   m.pieceStart.size());
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
    if (m.pieceStart.empty())
        return;
    thread_local std::vector<RawHit> hits;
    hits.clear();
    FilterContext collect{};
    rtcInitIntersectContext(&collect.context);
    collect.context.filter = filterHits;
    collect.scene = this;
    collect.collect = &hits;

    RTCRayHit rayHit{};
    rayHit.ray = makeRay(origin, dir, tMax);
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
    // A ray through the joint of two consecutive pieces of one strand hits
    // both ribbons within about a ribbon width (at most the widest): one crossing.
    thread_local std::vector<std::uint32_t> pieces; // the kept crossings' pieces
    pieces.clear();
    for (const RawHit& h : hits) {
        const std::uint32_t segment = m.pieceSegment[h.primID];
        const std::uint32_t strand = m.segmentStrand[segment];
        bool jointDuplicate = false;
        for (std::size_t k = out.size(); k-- > 0 && h.t - out[k].t <= 2 * width_;)
            jointDuplicate = jointDuplicate || (out[k].strand == strand &&
                                                (pieces[k] + 1 == h.primID || h.primID + 1 == pieces[k]));
        if (jointDuplicate)
            continue;
        const Vec3f p = origin + h.t * dir;
        out.push_back({h.t, strand, segment, m.arcLengthAt(segment, p), m.tangentAt(segment, p)});
        pieces.push_back(h.primID);
    }
}

void RayScene::filterHits(const RTCFilterFunctionNArguments* args) {
    const auto* c = reinterpret_cast<const FilterContext*>(args->context);
    const Impl& m = *c->scene->impl_;
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0)
            continue;
        const std::uint32_t piece = RTCHitN_primID(args->hit, args->N, i);
        const float t = RTCRayN_tfar(args->ray, args->N, i);
        const Vec3f p(RTCRayN_org_x(args->ray, args->N, i) + t * RTCRayN_dir_x(args->ray, args->N, i),
                      RTCRayN_org_y(args->ray, args->N, i) + t * RTCRayN_dir_y(args->ray, args->N, i),
                      RTCRayN_org_z(args->ray, args->N, i) + t * RTCRayN_dir_z(args->ray, args->N, i));
        if (m.offRibbon(piece, p)) {
            args->valid[i] = 0;
            continue;
        }
        if (c->collect) {
            c->collect->push_back({t, piece});
            args->valid[i] = 0; // keep traversing: every hit is wanted
            continue;
        }
        const std::uint32_t segment = m.pieceSegment[piece];
        if (c->from && m.segmentStrand[segment] == c->from->fiber.strand &&
            isOwnFiber(m.segmentStrand[segment], m.arcLengthAt(segment, p), c->from->fiber, t,
                       c->from->slack))
            args->valid[i] = 0;
    }
}

std::optional<RayHit> RayScene::intersect(const Vec3f& origin, const Vec3f& dir, float tMax,
                                          const RayOrigin* from) const {
    const Impl& m = *impl_;
    const std::optional<SurfaceHit> surface =
        surfaces_ ? surfaces_->intersect(origin, dir, tMax) : std::nullopt;
    const float tSurface = surface ? surface->t : tMax;
    RayHit hit;
    if (!m.pieceStart.empty()) {
        FilterContext context{};
        rtcInitIntersectContext(&context.context);
        context.context.filter = filterHits;
        context.scene = this;
        context.from = from;
        RTCRayHit rayHit{};
        rayHit.ray = makeRay(origin, dir, tSurface);
        rayHit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(m.scene, &context.context, &rayHit);
        if (rayHit.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
            const std::uint32_t segment = m.pieceSegment[rayHit.hit.primID];
            const Vec3f p = origin + rayHit.ray.tfar * dir;
            hit.kind = RayHit::Kind::Fiber;
            hit.t = rayHit.ray.tfar;
            hit.fiber = {m.segmentStrand[segment], segment, m.arcLengthAt(segment, p)};
            hit.tangent = m.tangentAt(segment, p);
            return hit;
        }
    }
    if (!surface)
        return std::nullopt;
    hit.kind = RayHit::Kind::Surface;
    hit.t = surface->t;
    hit.surface = surface->surface;
    hit.normal = surface->normal;
    hit.geometricNormal = surface->geometricNormal;
    return hit;
}

bool RayScene::occluded(const Vec3f& origin, const Vec3f& dir, float tMax,
                        const RayOrigin* from) const {
    if (surfaceOccluded(origin, dir, tMax))
        return true;
    const Impl& m = *impl_;
    if (m.pieceStart.empty())
        return false;
    FilterContext context{};
    rtcInitIntersectContext(&context.context);
    context.context.filter = filterHits;
    context.scene = this;
    context.from = from;
    RTCRay ray = makeRay(origin, dir, tMax);
    rtcOccluded1(m.scene, &context.context, &ray);
    return ray.tfar < 0; // Embree marks an occluded ray with tfar = −∞
}

bool RayScene::surfaceOccluded(const Vec3f& origin, const Vec3f& dir, float tMax) const {
    return surfaces_ && surfaces_->occluded(origin, dir, tMax);
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
