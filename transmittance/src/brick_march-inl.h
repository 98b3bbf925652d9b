// hairvox transmittance (internal): the rate volume's line integrals — the
// cell walk, the corners' ranks, the trilinear sums and Simpson's rule — as
// the static members of BrickMarch<Target>, whose body this is: brick_march.cpp
// includes it once per SIMD target (Highway's foreach_target.h), so that the
// lights' preparation uses the instructions its host has (a rank's popcount
// is one instruction from SSE4 up, a three-way min/max and the slab tests'
// blends are fewer), and BrickVolume's integrate(), integrateCumulative()
// and sample() dispatch to the best target at their first call. The
// arithmetic is elementwise in a fixed order and the file is compiled
// without contracting a·b + c into FMA, so every target gives the same bits.
// (No include guard: the body of one class per target.)

static constexpr float kInfinity = std::numeric_limits<float>::infinity();

/// The bits set in x: one instruction where the target has POPCNT
/// (brick_march.cpp), else popcount64's arithmetic.
static int bitCount(std::uint64_t x) {
#if HWY_TARGET <= HWY_AVX2
    return __builtin_popcountll(x);
#else
    return popcount64(x);
#endif
}

/// Four floats in a SIMD register (GCC's and Clang's vector extension).
using Half = float __attribute__((vector_size(16)));
/// A Lanes value in registers as kParts vectors of kPartLanes floats: one
/// of 8 where the target has AVX, else two of 4 (SSE; the scalar target's
/// compiler splits them further). The arithmetic is elementwise in the same
/// order at every width, so the same bits; loops over the 8 floats kept
/// their sums in memory between corners.
#if HWY_TARGET <= HWY_AVX2
static constexpr int kPartLanes = 8;
#else
static constexpr int kPartLanes = 4;
#endif
static constexpr int kParts = 8 / kPartLanes;
using Part = float __attribute__((vector_size(sizeof(float) * kPartLanes)));

static Part loadPart(const Lanes& v, int h) {
    Part r;
    std::memcpy(&r, v.v + kPartLanes * h, sizeof(r));
    return r;
}

static void storePart(Lanes& v, int h, const Part& r) {
    std::memcpy(v.v + kPartLanes * h, &r, sizeof(r));
}

/// The trilinear weights of the 8 corners k = dx·4 + dy·2 + dz at fractions
/// f, each (wx·wy)·wz: all 8 in four vector products, where each corner's
/// own three loads and two products took more than its sums.
struct CornerWeights {
    alignas(16) float w[8];

    explicit CornerWeights(const Vec3f& f) {
        const float x0 = 1.0f - f.x, y0 = 1.0f - f.y, z0 = 1.0f - f.z;
        const Half xy = Half{x0, x0, f.x, f.x} * Half{y0, f.y, y0, f.y};
        const Half z = {z0, f.z, z0, f.z};
        const Half low = Half{xy[0], xy[0], xy[1], xy[1]} * z;  // dx = 0
        const Half high = Half{xy[2], xy[2], xy[3], xy[3]} * z; // dx = 1
        std::memcpy(w, &low, sizeof(low));
        std::memcpy(w + 4, &high, sizeof(high));
    }
};

/// Trilinear interpolation of a cell's corners at fractions f. The corners
/// left out are zero, so the sum is the 8-corner sum, bit for bit (adding
/// w·0 to a non-negative sum leaves it as it is).
static Lanes trilinear(const CellCorners& c, const Vec3f& f) {
    const CornerWeights weights(f);
    Part r[kParts] = {};
    for (int i = 0; i < c.count; ++i) {
        const float w = weights.w[c.k[std::size_t(i)]];
        const Lanes& v = *c.value[std::size_t(i)];
        for (int h = 0; h < kParts; ++h)
            r[h] += w * loadPart(v, h);
    }
    Lanes result;
    for (int h = 0; h < kParts; ++h)
        storePart(result, h, r[h]);
    return result;
}

/// trilinear() at fractions f and g together (a piece's middle and end): the
/// same sums in the same order, as independent chains of additions where
/// one evaluation after the other waited on each add's latency.
static void trilinear2(const CellCorners& c, const Vec3f& f, const Vec3f& g, Lanes& atF,
                       Lanes& atG) {
    const CornerWeights weightsF(f), weightsG(g);
    Part rf[kParts] = {}, rg[kParts] = {};
    for (int i = 0; i < c.count; ++i) {
        const std::size_t k = c.k[std::size_t(i)];
        const float wf = weightsF.w[k], wg = weightsG.w[k];
        const Lanes& v = *c.value[std::size_t(i)];
        for (int h = 0; h < kParts; ++h) {
            const Part part = loadPart(v, h);
            rf[h] += wf * part;
            rg[h] += wg * part;
        }
    }
    for (int h = 0; h < kParts; ++h) {
        storePart(atF, h, rf[h]);
        storePart(atG, h, rg[h]);
    }
}

/// a += w·(f0 + 4 fm + f1), lane by lane.
static void addSimpson(Lanes& a, const Lanes& f0, const Lanes& fm, const Lanes& f1, float w) {
    for (int h = 0; h < kParts; ++h)
        storePart(a, h,
                  loadPart(a, h) +
                      w * (loadPart(f0, h) + 4.0f * loadPart(fm, h) + loadPart(f1, h)));
}

/// Where the cell walk of `line` over s ∈ [s0, s1) through brick `brick`
/// (at brick coordinate b) may enter a cell a value is a corner of: false
/// where it cannot (the line misses the boxes of those cells, widened
/// against rounding), else [sa, sb] ⊆ [s0, s1] covering every box it
/// meets. Outside [sa, sb] the line crosses only cells without a value,
/// whose pieces add nothing, and at sa > s0 it is in such a cell (a
/// widened box's face lies a margin outside every box), where the walk
/// would have arrived with a zero field too: walking [sa, sb] instead of
/// [s0, s1), or skipping the brick, leaves every result as it was. At
/// 0.5 mm on Ratboy a line meets ~3 cells with values of the ~10 it
/// crosses in a brick.
static bool valueSpan(const BrickVolume& v, std::size_t brick, const glm::ivec3& b,
                      const GridLine<float>& line, float s0, float s1, float& spanBegin,
                      float& spanEnd) {
    const BrickVolume::OctantBoxes& boxes = v.cellBoxes_[brick];
    spanBegin = s0;
    spanEnd = s1;
    if (boxes.whole)
        return true;
    spanBegin = kInfinity;
    spanEnd = -kInfinity;
    const glm::ivec3 base = BrickVolume::kBrick * b;
    // The walk's crossings are exact to a few ulps of the index coordinates:
    // 1/64 of a cell, more where the coordinates are large.
    const int magnitude =
        std::max({std::abs(base.x), std::abs(base.y), std::abs(base.z)}) + BrickVolume::kBrick;
    const float margin = 1.0f / 64.0f + 64.0f * std::numeric_limits<float>::epsilon() *
                                            static_cast<float>(magnitude);
#if HWY_TARGET <= HWY_AVX2
    // The 8 octants' slab tests side by side, one octant a lane: the same
    // operations on the same values as the loop below, so the same span.
    namespace hn = hwy::HWY_NAMESPACE;
    const hn::FixedTag<float, 8> df;
    const hn::RebindToSigned<decltype(df)> di;
    const hn::Rebind<std::uint8_t, decltype(di)> d8;
    auto sa = hn::Set(df, s0), sb = hn::Set(df, s1);
    const auto present = hn::RebindMask( // lo ≤ hi (Highway 1.0 has no integer Le)
        df, hn::Not(hn::Gt(hn::PromoteTo(di, hn::LoadU(d8, boxes.lo[0].data())),
                           hn::PromoteTo(di, hn::LoadU(d8, boxes.hi[0].data())))));
    for (std::size_t a = 0; a < 3; ++a) {
        const int i = static_cast<int>(a);
        const auto lo = hn::Sub(
            hn::ConvertTo(df, hn::Add(hn::Set(di, base[i]),
                                      hn::PromoteTo(di, hn::LoadU(d8, boxes.lo[a].data())))),
            hn::Set(df, margin));
        const auto hi = hn::Add(
            hn::ConvertTo(df, hn::Add(hn::Set(di, base[i] + 1),
                                      hn::PromoteTo(di, hn::LoadU(d8, boxes.hi[a].data())))),
            hn::Set(df, margin));
        if (line.invDir[i] == 0.0f) { // the walk does not move along a
            const auto x = hn::Set(df, line.origin[i] + s0 * line.dir[i]);
            sb = hn::IfThenElse(hn::Or(hn::Lt(x, lo), hn::Gt(x, hi)), hn::Set(df, -kInfinity), sb);
            continue;
        }
        const auto o = hn::Set(df, line.origin[i]), inv = hn::Set(df, line.invDir[i]);
        const auto ta = hn::Mul(hn::Sub(lo, o), inv), tb = hn::Mul(hn::Sub(hi, o), inv);
        sa = hn::Max(sa, hn::Min(ta, tb));
        sb = hn::Min(sb, hn::Max(ta, tb));
    }
    const auto meets = hn::And(present, hn::Le(sa, sb));
    spanBegin = hn::GetLane(hn::MinOfLanes(df, hn::IfThenElse(meets, sa, hn::Set(df, kInfinity))));
    spanEnd = hn::GetLane(hn::MaxOfLanes(df, hn::IfThenElse(meets, sb, hn::Set(df, -kInfinity))));
#else
    for (std::size_t octant = 0; octant < 8; ++octant) {
        if (boxes.lo[0][octant] > boxes.hi[0][octant])
            continue; // an octant without such cells
        float sa = s0, sb = s1;
        for (std::size_t a = 0; a < 3 && sa <= sb; ++a) {
            const int i = static_cast<int>(a);
            const float lo = static_cast<float>(base[i] + boxes.lo[a][octant]) - margin;
            const float hi = static_cast<float>(base[i] + boxes.hi[a][octant] + 1) + margin;
            if (line.invDir[i] == 0.0f) { // the walk does not move along a
                const float x = line.origin[i] + s0 * line.dir[i];
                if (x < lo || x > hi)
                    sb = -kInfinity;
                continue;
            }
            const float ta = (lo - line.origin[i]) * line.invDir[i];
            const float tb = (hi - line.origin[i]) * line.invDir[i];
            sa = std::max(sa, std::min(ta, tb));
            sb = std::min(sb, std::max(ta, tb));
        }
        if (sa <= sb) {
            spanBegin = std::min(spanBegin, sa);
            spanEnd = std::max(spanEnd, sb);
        }
    }
#endif
    return spanBegin <= spanEnd;
}

/// The corners holding a value of the cell at `cell` ∈ [0, 8)³ of brick `brick`.
static CellCorners cornersOf(const BrickVolume& v, std::size_t brick, const glm::ivec3& cell) {
    CellCorners corners;
    const BrickVolume::SlotBits& present = v.present_[brick];
    const Lanes* values = v.values_.data() + v.valueBase_[brick];
    const int first = BrickVolume::valueIndex(cell.x, cell.y, cell.z);
    // Corner k = dx·4 + dy·2 + dz: each (dx, dy) has its dz = 0 and 1 on
    // adjacent slots, so one rank (valueAt()'s) serves both.
    for (int pair = 0; pair < 4; ++pair) {
        const int slot = first + (pair >> 1) * BrickVolume::kSide * BrickVolume::kSide +
                         (pair & 1) * BrickVolume::kSide;
        const auto w = static_cast<std::size_t>(slot >> 6);
        const int bit = slot & 63;
        const std::uint64_t word = present.bits[w];
        std::size_t rank =
            present.rank[w] + std::size_t(bitCount(word & ((std::uint64_t(1) << bit) - 1)));
        // (The dz = 1 slot is the next bit, in the next word after bit 63;
        // slots end at 728, so that word exists.)
        const std::uint64_t high = bit < 63 ? word >> (bit + 1) : present.bits[w + 1];
        if ((word >> bit) & 1u) {
            const auto n = std::size_t(corners.count++);
            corners.k[n] = static_cast<std::uint8_t>(2 * pair);
            corners.value[n] = values + rank++;
        }
        if (high & 1u) {
            const auto n = std::size_t(corners.count++);
            corners.k[n] = static_cast<std::uint8_t>(2 * pair + 1);
            corners.value[n] = values + rank;
        }
    }
    return corners;
}

/// Calls visit(brickIndex, brickCoord, sEnter, sExit) for the bricks that
/// exist along O + s·dir (index space), s ∈ [s0, s1), in order, while it
/// returns true.
template <typename F>
static void walkBricks(const BrickVolume& v, const Vec3f& O, const Vec3f& dir, float s0, float s1,
                       F&& visit) {
    if (v.empty())
        return;
    const Vec3f lo = Vec3f(BrickVolume::kBrick * v.brickMin_),
                hi = Vec3f(BrickVolume::kBrick * (v.brickMax_ + 1));
    for (int a = 0; a < 3; ++a) { // clip to the bricks' bounding box
        if (dir[a] == 0.0f) {
            if (O[a] < lo[a] || O[a] > hi[a])
                return;
            continue;
        }
        const float ta = (lo[a] - O[a]) / dir[a], tb = (hi[a] - O[a]) / dir[a];
        s0 = std::max(s0, std::min(ta, tb));
        s1 = std::min(s1, std::max(ta, tb));
    }
    if (!(s0 < s1))
        return;
    // Bricks are cells 8 index units wide, super-bricks 8·BrickVolume::kSuper: traverse
    // the line scaled by 1/(8·BrickVolume::kSuper), then by 1/8 within the occupied ones.
    const GridLine<float> inSupers(O / float(BrickVolume::kBrick * BrickVolume::kSuper),
                                   dir / float(BrickVolume::kBrick * BrickVolume::kSuper));
    const GridLine<float> inBricks(O / float(BrickVolume::kBrick),
                                   dir / float(BrickVolume::kBrick));
    traverseCells(
        inSupers, s0, s1, v.superMin_, v.superMax_,
        [&](const glm::ivec3& sb, float sEnterSuper, float sExitSuper) {
            if (!v.superOccupied(sb))
                return true;
            return traverseCells(
                inBricks, sEnterSuper, sExitSuper, glm::max(sb * BrickVolume::kSuper, v.brickMin_),
                glm::min(sb * BrickVolume::kSuper + (BrickVolume::kSuper - 1), v.brickMax_),
                [&](const glm::ivec3& b, float sEnter, float sExit) {
                    if (!v.occupied(b))
                        return true;
                    return visit(static_cast<std::size_t>(v.find(b)), b, sEnter, sExit);
                });
        });
}

/// Walks the cells of one brick over s ∈ [sa, sb), cut further at
/// nextSplit(s) (the next cut after s), calling onPiece(s0, s1, f0, fm, f1)
/// with the field at each piece's ends and middle (nothing for cells whose
/// corners are all zero).
template <typename NextSplit, typename OnPiece>
static void forEachPiece(const BrickVolume& v, std::size_t brick, const glm::ivec3& b,
                         const GridLine<float>& line, float sa, float sb, NextSplit&& nextSplit,
                         OnPiece&& onPiece) {
    const glm::ivec3 base = BrickVolume::kBrick * b;
    // The field is continuous: a piece's end value is the next piece's start value.
    Lanes fStart;
    bool haveStart = false;
    traverseCells(line, sa, sb, base, base + (BrickVolume::kBrick - 1),
                  [&](const glm::ivec3& cell, float s, float sEnd) {
                      const glm::ivec3 l = cell - base;
                      if (!((v.cellMask_[brick][std::size_t(l.x)] >> (l.y * 8 + l.z)) & 1u)) {
                          fStart = Lanes{}; // no corner holds a value
                          haveStart = true;
                          return true;
                      }
                      const CellCorners corners = cornersOf(v, brick, l);
                      bool any = false;
                      for (int i = 0; i < corners.count; ++i)
                          any = any || corners.value[std::size_t(i)]->v[0] != 0.0f;
                      if (!any) {
                          fStart = Lanes{};
                          haveStart = true;
                          return true;
                      }
                      const Vec3f cf(cell);
                      const auto at = [&](float t) {
                          return trilinear(corners, line.at(t) - cf);
                      };
                      if (!haveStart)
                          fStart = at(s);
                      haveStart = true;
                      for (float a = s; a < sEnd;) {
                          const float e = std::min(nextSplit(a), sEnd);
                          Lanes fMid, fEnd;
                          trilinear2(corners, line.at(0.5f * (a + e)) - cf, line.at(e) - cf, fMid,
                                     fEnd);
                          onPiece(a, e, fStart, fMid, fEnd);
                          fStart = fEnd;
                          a = e;
                      }
                      return true;
                  });
}

/// BrickVolume::integrate().
static OpticalDepths integrate(const BrickVolume& v, const Vec3f& origin, const Vec3f& dir,
                               float tStart, float tEnd, float opaqueDepth, bool& touched) {
    // Index space: p(s) = O + s·dir with s = t/h; the sum is scaled by h at the end.
    // Simpson's rule per cell piece is exact: the trilinear field is a cubic along a line.
    const Vec3f O = origin * v.invH_;
    const float opaqueSum = opaqueDepth * v.invH_;
    Lanes sum;
    touched = false;
    const GridLine<float> line(O, dir);
    walkBricks(v, O, dir, tStart * v.invH_, std::isinf(tEnd) ? kInfinity : tEnd * v.invH_,
               [&](std::size_t brick, const glm::ivec3& b, float s, float sExit) {
                   touched = true;
                   float sa, sb;
                   if (!valueSpan(v, brick, b, line, s, sExit, sa, sb))
                       return true;
                   forEachPiece(
                       v, brick, b, line, sa, sb, [](float) { return kInfinity; },
                       [&](float s0, float s1, const Lanes& f0, const Lanes& fm, const Lanes& f1) {
                           addSimpson(sum, f0, fm, f1, (s1 - s0) / 6.0f);
                       });
                   return !sum.opaque(opaqueSum);
               });
    return sum.depths() * static_cast<float>(v.h_);
}

/// BrickVolume::integrateCumulative().
static void integrateCumulative(const BrickVolume& v, const Vec3f& origin, const Vec3f& dir,
                                float tStart, float step, std::size_t count, float opaqueDepth,
                                std::span<const std::uint32_t> candidates,
                                std::vector<BrickVolume::BrickCrossing>& crossings,
                                std::vector<BrickVolume::CumulativeSample>& out) {
    out.clear();
    if (count == 0)
        return;
    const Vec3f O = origin * v.invH_;
    const float opaqueSum = opaqueDepth * v.invH_;
    const float sStart = tStart * v.invH_, sStep = step * v.invH_;
    const auto position = [&](std::size_t k) {
        return sStart + static_cast<float>(k) * sStep;
    };
    Lanes sum;
    std::size_t next = 0;       // the next sample to record
    float nextAt = position(0); // its position; +∞ once every sample is recorded
    const auto setNext = [&](std::size_t k) {
        next = k;
        nextAt = k < count ? position(k) : kInfinity;
    };
    // Records sample `next` with the running sum (in world units).
    const auto recordNext = [&] {
        out.push_back({next, sum});
        for (float& lane : out.back().value.v)
            lane *= static_cast<float>(v.h_);
        setNext(next + 1);
    };
    // Records every sample from `next` to the last at or before s.
    const auto recordUpTo = [&](float s) {
        while (nextAt <= s)
            recordNext();
    };
    // Entering a brick at s: the samples since the last brick hold the
    // current sum. The first of them (which the last brick's exit changed)
    // and the last (which the brick's first piece interpolates from) are
    // recorded; those between are skipped.
    const auto skipTo = [&](float s) {
        if (nextAt <= s)
            recordNext();
        const float local = std::floor((s - sStart) / sStep);
        std::size_t k = local > 0 ? std::min(static_cast<std::size_t>(local), count - 1) : 0;
        while (k > 0 && position(k) > s) // float rounding either side of a sample
            --k;
        while (k + 1 < count && position(k + 1) <= s)
            ++k;
        if (k > next)
            setNext(k);
    };
    // The candidates the line crosses over [sStart, position(count − 1)], in
    // order along it (bricks are disjoint: their crossings do not overlap).
    const GridLine<float> line(O, dir);
    crossings.clear();
    for (const std::uint32_t brick : candidates) {
        const Vec3f lo(BrickVolume::kBrick * v.brickCoord_[brick]),
            hi = lo + float(BrickVolume::kBrick);
        float s0 = sStart, s1 = position(count - 1);
        for (int a = 0; a < 3; ++a) {
            if (line.invDir[a] == 0.0f) {
                // Parallel to the slab: inside it or not at all. On a face
                // between two bricks, in the upper one only (⌊x⌋, as a
                // walk through the cells takes it).
                if (O[a] < lo[a] || O[a] >= hi[a])
                    s1 = -kInfinity;
                continue;
            }
            const float ta = (lo[a] - O[a]) * line.invDir[a], tb = (hi[a] - O[a]) * line.invDir[a];
            s0 = std::max(s0, std::min(ta, tb));
            s1 = std::min(s1, std::max(ta, tb));
        }
        if (s0 < s1)
            crossings.push_back({s0, s1, brick});
    }
    std::sort(crossings.begin(), crossings.end(),
              [](const BrickVolume::BrickCrossing& x, const BrickVolume::BrickCrossing& y) {
                  return x.sEnter < y.sEnter || (x.sEnter == y.sEnter && x.brick < y.brick);
              });
    for (const BrickVolume::BrickCrossing& crossing : crossings) {
        // A brick the line crosses no value's cell of leaves the sum and
        // what is recorded as they were (the samples it would record repeat
        // the last value; the next brick's skipTo records the same ones
        // either side of a change).
        const glm::ivec3& b = v.brickCoord_[crossing.brick];
        float sa, sb;
        if (!valueSpan(v, crossing.brick, b, line, crossing.sEnter, crossing.sExit, sa, sb))
            continue;
        skipTo(sa);
        recordUpTo(sa);
        // Pieces end at sample positions, where the running sum is recorded.
        forEachPiece(
            v, crossing.brick, b, line, sa, sb,
            [&](float t) {
                // (floorToInt: std::floor is a long sequence on x86-64's
                // baseline; t lies within the line's samples, whose count is
                // far below 2^31, where both give the same float.)
                const float k = static_cast<float>(floorToInt((t - sStart) / sStep)) + 1.0f;
                const float split = sStart + k * sStep;
                return split > t ? split : split + sStep; // rounding at a sample
            },
            [&](float s0, float s1, const Lanes& f0, const Lanes& fm, const Lanes& f1) {
                // The samples up to the piece hold the sum before it:
                // those between the brick's entry and its first cell
                // with values are recorded here, not after it.
                recordUpTo(s0);
                addSimpson(sum, f0, fm, f1, (s1 - s0) / 6.0f);
                recordUpTo(s1);
            });
        if (sum.opaque(opaqueSum))
            return; // later samples would only grow
    }
    if (next < count)
        recordNext(); // the first sample after the last brick: the final value
}

/// BrickVolume::sample().
static OpticalDepths sample(const BrickVolume& v, const Vec3f& position) {
    const Vec3f q = position * v.invH_;
    const glm::ivec3 c(glm::floor(q));
    const glm::ivec3 b = c >> 3; // floor division by the brick size (C++20: arithmetic shift)
    const std::int64_t brick = v.find(b);
    if (brick < 0)
        return {};
    const glm::ivec3 l = c - BrickVolume::kBrick * b;
    return trilinear(cornersOf(v, static_cast<std::size_t>(brick), l), q - Vec3f(c)).depths();
}
