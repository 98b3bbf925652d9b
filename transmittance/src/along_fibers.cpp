// The global term sampled along the fibers and interpolated (alongFibers(),
// global_term_model.h).
#include <hairvox/core/thread_scratch.h>
#include <hairvox/transmittance/global_term_model.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace hairvox {

namespace {

class AlongFibers final : public LightGlobalTerm {
public:
    AlongFibers(std::unique_ptr<LightGlobalTerm> inner, const Groom& groom, float spacing,
                bool shareVertices)
        : inner_(std::move(inner))
        , groom_(groom)
        , spacing_(spacing)
        , shareVertices_(shareVertices) {}

    std::size_t memoryBytes() const override { return inner_->memoryBytes(); }
    bool blocksEverything() const override { return inner_->blocksEverything(); }

    GlobalTermStats evaluate(std::span<const GlobalTermQuery> queries,
                             std::span<GlobalTerm> out) const override {
        struct Scratch {
            FiberSamplePlan plan;
            std::vector<GlobalTerm> values;
        };
        ThreadScratch<Scratch> scratch;
        auto& [plan, values] = *scratch;
        plan.plan(queries, groom_, spacing_, shareVertices_);
        values.resize(plan.samples().size()); // every element written by the inner term
        GlobalTermStats stats = inner_->evaluate(plan.samples(), values);
        plan.interpolate(values, out);
        stats.queries = queries.size();
        return stats;
    }

private:
    std::unique_ptr<LightGlobalTerm> inner_;
    const Groom& groom_;
    float spacing_;
    bool shareVertices_;
};

} // namespace

void FiberSamplePlan::plan(std::span<const GlobalTermQuery> queries, const Groom& groom,
                           float spacing, bool shareVertices) {
    const std::vector<Vec3f>& points = groom.points;
    // Per query: the sample at or below it and the fraction toward the next
    // one, which is the sample after it; a query on a sample (f = 0: a strand
    // vertex, as the vertex rate and the tail shade) needs that sample alone.
    samples_.clear();
    where_.resize(queries.size());
    // The last sample planned, when it is the tip-side vertex of the segment
    // of the run before: (that segment's root-side point, its strand).
    std::uint32_t vertexAfter = kUnknownSegment, vertexStrand = kUnknownStrand;
    std::size_t i = 0;
    while (i < queries.size()) {
        const GlobalTermQuery& q = queries[i];
        if (q.segment == kUnknownSegment || !q.onFiber ||
            std::size_t(q.segment) + 1 >= points.size()) {
            where_[i++] = {static_cast<std::uint32_t>(samples_.size()), 0.0f};
            samples_.push_back(q);
            vertexAfter = kUnknownSegment;
            continue;
        }
        // The run of queries on this segment, each at t = x/m, x ∈ [k, k + 1].
        const Vec3f p0 = points[q.segment], d = points[q.segment + 1] - p0;
        const float length2 = glm::dot(d, d);
        // (At least 1 — also for a NaN length — and capped, so that an
        // absurd length/spacing ratio cannot overflow the sample index.)
        const float ratio = std::sqrt(length2) / spacing;
        const int m =
            ratio > 1.0f ? static_cast<int>(std::min(std::ceil(ratio), float(1 << 30))) : 1;
        const float scale = length2 > 0 ? float(m) / length2 : 0.0f;
        std::size_t end = i;
        int kMin = m, kMax = 0; // the first and last sample needed
        for (; end < queries.size() && queries[end].segment == q.segment && queries[end].onFiber;
             ++end) {
            const float along = glm::dot(queries[end].position - p0, d) * scale;
            const float x = along > 0 ? std::min(along, float(m)) : 0.0f; // NaN → 0
            const int k = static_cast<int>(x);
            where_[end] = {static_cast<std::uint32_t>(k), x - float(k)};
            kMin = std::min(kMin, k);
            kMax = std::max(kMax, where_[end].f > 0 ? k + 1 : k);
        }
        // The samples the run needs: all of kMin ... kMax when the queries
        // lie dense along the segment (the common case: several fragments per
        // sample), else just each query's k and, between samples, k + 1 (a
        // long segment seen from afar). Either way a query's value depends
        // only on its own position, not on the batch.
        needed_.clear();
        const bool dense = std::size_t(kMax - kMin + 1) <= 2 * (end - i);
        if (dense) {
            for (int k = kMin; k <= kMax; ++k)
                needed_.push_back(k);
        } else {
            for (std::size_t j = i; j < end; ++j) {
                needed_.push_back(static_cast<int>(where_[j].sample));
                if (where_[j].f > 0)
                    needed_.push_back(static_cast<int>(where_[j].sample) + 1);
            }
            std::sort(needed_.begin(), needed_.end());
            needed_.erase(std::unique(needed_.begin(), needed_.end()), needed_.end());
        }
        // The run before ended on this segment's root-side vertex: that
        // sample is this run's first (k = 0), the same position and strand.
        const bool shared = shareVertices && vertexAfter != kUnknownSegment &&
                            vertexAfter + 1 == q.segment && vertexStrand == q.strand &&
                            needed_.front() == 0;
        const auto base = static_cast<std::uint32_t>(samples_.size() - (shared ? 1 : 0));
        const Vec3f tangent = normalizeOr(d, q.tangent);
        for (std::size_t n = shared ? 1 : 0; n < needed_.size(); ++n) {
            const int k = needed_[n];
            // Field by field into the array: a whole query built on the stack
            // and copied was read back in 16-byte pieces over its 1-byte
            // fields just stored, a store-forwarding stall (its two
            // instructions took a fifth of this function's samples on the
            // head; the function's samples fell 7%).
            GlobalTermQuery& sample = samples_.emplace_back();
            // The ends are the strand's vertices exactly (p0 + 1·d may round
            // away from p1), so that the two segments meeting there agree.
            sample.position = k == m ? points[q.segment + 1] : p0 + (float(k) / float(m)) * d;
            sample.tangent = tangent;
            sample.strand = q.strand;
            sample.onFiber = true;
            sample.fiberType = q.fiberType;
            sample.segment = q.segment;
        }
        for (std::size_t j = i; j < end; ++j) {
            const int k = static_cast<int>(where_[j].sample);
            const auto offset =
                dense ? k - kMin
                      : std::lower_bound(needed_.begin(), needed_.end(), k) - needed_.begin();
            where_[j].sample = base + static_cast<std::uint32_t>(offset);
        }
        vertexAfter = needed_.back() == m ? q.segment : kUnknownSegment;
        vertexStrand = q.strand;
        i = end;
    }
}

std::unique_ptr<LightGlobalTerm> alongFibers(std::unique_ptr<LightGlobalTerm> inner,
                                             const Groom& groom, float spacing,
                                             bool shareVertices) {
    if (!(spacing > 0))
        return inner;
    return std::make_unique<AlongFibers>(std::move(inner), groom, spacing, shareVertices);
}

} // namespace hairvox
