// hairvox transmittance: probing the global term at points on fibers, and
// measuring one mode against another (docs/DESIGN.md §6, probe level).
//
// CSV formats (the `hairvox probe` command):
//   points   header `x,y,z,tx,ty,tz[,strand]` — a point on a fiber and that
//            fiber's tangent (normalised on reading), optionally its strand index;
//   results  the input columns, then `n,V,P_r,P_g,P_b,Ts_r,Ts_g,Ts_b,sf2_r,sf2_g,sf2_b`.
#pragma once

#include <hairvox/strands/groom.h>
#include <hairvox/transmittance/global_term_model.h>

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

namespace hairvox {

/// N points uniformly distributed over the groom's fiber length (a segment
/// chosen with probability proportional to its length, a uniform position on
/// it), with the segment's tangent and the strand index. Deterministic by seed.
std::vector<GlobalTermQuery> sampleFiberPoints(const Groom& groom, std::size_t count,
                                               std::uint64_t seed);

/// Reads a points CSV; InputError naming the file, line and column on bad input.
std::vector<GlobalTermQuery> readProbePoints(const std::filesystem::path& path);
/// Writes a points CSV (with the strand column) atomically.
void writeProbePoints(const std::filesystem::path& path, std::span<const GlobalTermQuery> points);
/// Writes the results CSV atomically; `terms` matches `points` row by row.
void writeProbeResults(const std::filesystem::path& path, std::span<const GlobalTermQuery> points,
                       std::span<const GlobalTerm> terms);

/// How far an estimate is from a reference over the same points.
struct ProbeError {
    double maeV = 0;     ///< mean |V − V_ref|
    double maeT_s = 0;   ///< mean |T_s − T_s,ref| over points and RGB channels
    double biasN = 0;    ///< mean (n − n_ref)
    double meanNRef = 0; ///< mean n_ref, for scale
};

ProbeError compareGlobalTerms(std::span<const GlobalTerm> estimate,
                              std::span<const GlobalTerm> reference);

/// Evaluates one light for all points (a convenience for probes and tests).
std::vector<GlobalTerm> evaluateGlobalTerm(const GlobalTermModel& model, const Light& light,
                                           std::span<const GlobalTermQuery> points);

} // namespace hairvox
