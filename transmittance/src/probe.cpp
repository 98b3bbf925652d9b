#include <hairvox/core/atomic_file.h>
#include <hairvox/core/error.h>
#include <hairvox/core/rng.h>
#include <hairvox/transmittance/probe.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <string_view>

namespace hairvox {

std::vector<GlobalTermQuery> sampleFiberPoints(const Groom& groom, std::size_t count,
                                               std::uint64_t seed) {
    std::vector<double> cumulative; // cumulative segment length
    std::vector<std::uint32_t> segmentStrand, segmentStart;
    double total = 0;
    for (std::size_t s = 0; s < groom.strandCount(); ++s)
        for (std::uint32_t i = groom.strandStart[s]; i + 1 < groom.strandStart[s + 1]; ++i) {
            total += double(glm::distance(groom.points[i], groom.points[i + 1]));
            cumulative.push_back(total);
            segmentStrand.push_back(static_cast<std::uint32_t>(s));
            segmentStart.push_back(i);
        }
    std::vector<GlobalTermQuery> points;
    if (cumulative.empty() || !(total > 0))
        return points;
    points.reserve(count);
    Pcg32 rng(seed, 0x9e0b3);
    for (std::size_t k = 0; k < count; ++k) {
        const double target = rng.uniformDouble() * total;
        const auto seg = static_cast<std::size_t>(std::min<std::ptrdiff_t>(
            std::upper_bound(cumulative.begin(), cumulative.end(), target) - cumulative.begin(),
            static_cast<std::ptrdiff_t>(cumulative.size()) - 1));
        const Vec3f a = groom.points[segmentStart[seg]], b = groom.points[segmentStart[seg] + 1];
        const float t = rng.uniformFloat();
        points.push_back({lerp(t, a, b), normalizeOr(b - a, Vec3f(0, 1, 0)), segmentStrand[seg],
                          true, fiberTypeAt(groom, segmentStart[seg])});
    }
    return points;
}

namespace {

std::vector<std::string_view> splitCsv(std::string_view line) {
    std::vector<std::string_view> fields;
    std::size_t start = 0;
    for (;;) {
        const std::size_t comma = line.find(',', start);
        std::string_view f =
            line.substr(start, comma == std::string_view::npos ? comma : comma - start);
        while (!f.empty() && (f.front() == ' ' || f.front() == '\t'))
            f.remove_prefix(1);
        while (!f.empty() && (f.back() == ' ' || f.back() == '\t' || f.back() == '\r'))
            f.remove_suffix(1);
        fields.push_back(f);
        if (comma == std::string_view::npos)
            return fields;
        start = comma + 1;
    }
}

} // namespace

std::vector<GlobalTermQuery> readProbePoints(const std::filesystem::path& path) {
    std::ifstream in(path);
    if (!in)
        throw InputError(strCat(path.string(), ": cannot open"));
    std::string line;
    if (!std::getline(in, line))
        throw InputError(strCat(path.string(), ": empty file (expected header x,y,z,tx,ty,tz)"));
    const auto header = splitCsv(line);
    const bool hasStrand = header.size() == 7 && header[6] == "strand";
    const std::vector<std::string_view> expected{"x", "y", "z", "tx", "ty", "tz"};
    if (!(header.size() == 6 || hasStrand) ||
        !std::equal(expected.begin(), expected.end(), header.begin()))
        throw InputError(strCat(path.string(), ":1: header must be x,y,z,tx,ty,tz[,strand]"));

    std::vector<GlobalTermQuery> points;
    for (std::size_t lineNumber = 2; std::getline(in, line); ++lineNumber) {
        if (line.empty() || line == "\r")
            continue;
        const auto fields = splitCsv(line);
        if (fields.size() != header.size())
            throw InputError(strCat(path.string(), ":", lineNumber, ": expected ", header.size(),
                                    " columns, found ", fields.size()));
        float v[6];
        for (int c = 0; c < 6; ++c) {
            const std::string_view f = fields[static_cast<std::size_t>(c)];
            const auto [end, ec] = std::from_chars(f.data(), f.data() + f.size(), v[c]);
            if (ec != std::errc() || end != f.data() + f.size() || !std::isfinite(v[c]))
                throw InputError(strCat(path.string(), ":", lineNumber, ": column ",
                                        expected[std::size_t(c)], ": '", f,
                                        "' is not a finite number"));
        }
        const Vec3f tangent(v[3], v[4], v[5]);
        if (!(glm::length(tangent) > 1e-12f))
            throw InputError(strCat(path.string(), ":", lineNumber, ": the tangent is zero"));
        GlobalTermQuery q{Vec3f(v[0], v[1], v[2]), glm::normalize(tangent)};
        if (hasStrand) {
            const std::string_view f = fields[6];
            const auto [end, ec] = std::from_chars(f.data(), f.data() + f.size(), q.strand);
            if (ec != std::errc() || end != f.data() + f.size())
                throw InputError(strCat(path.string(), ":", lineNumber, ": column strand: '", f,
                                        "' is not a strand index"));
        }
        points.push_back(q);
    }
    return points;
}

namespace {

void writeCsv(const std::filesystem::path& path, const std::string& text) {
    writeFileAtomically(path, [&](const std::filesystem::path& tmp) {
        std::ofstream out(tmp, std::ios::trunc);
        out << text;
        out.flush();
        if (!out)
            throw InputError(strCat(path.string(), ": write failed"));
    });
}

std::string pointColumns(const GlobalTermQuery& q) {
    char buf[256];
    std::snprintf(buf, sizeof(buf), "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g", double(q.position.x),
                  double(q.position.y), double(q.position.z), double(q.tangent.x),
                  double(q.tangent.y), double(q.tangent.z));
    return buf;
}

} // namespace

void writeProbePoints(const std::filesystem::path& path, std::span<const GlobalTermQuery> points) {
    std::string text = "x,y,z,tx,ty,tz,strand\n";
    for (const GlobalTermQuery& q : points)
        text += pointColumns(q) + "," + std::to_string(q.strand) + "\n";
    writeCsv(path, text);
}

void writeProbeResults(const std::filesystem::path& path, std::span<const GlobalTermQuery> points,
                       std::span<const GlobalTerm> terms) {
    std::string text = "x,y,z,tx,ty,tz,n,V,P_r,P_g,P_b,Ts_r,Ts_g,Ts_b,sf2_r,sf2_g,sf2_b\n";
    for (std::size_t i = 0; i < points.size(); ++i) {
        const GlobalTerm& g = terms[i];
        char buf[512];
        std::snprintf(buf, sizeof(buf), ",%.7g,%.7g,%.7g,%.7g,%.7g,%.7g,%.7g,%.7g,%.7g,%.7g,%.7g\n",
                      double(g.n), double(g.V), double(g.P.r), double(g.P.g), double(g.P.b),
                      double(g.T_s.r), double(g.T_s.g), double(g.T_s.b), double(g.sigma2_f.r),
                      double(g.sigma2_f.g), double(g.sigma2_f.b));
        text += pointColumns(points[i]) + buf;
    }
    writeCsv(path, text);
}

ProbeError compareGlobalTerms(std::span<const GlobalTerm> estimate,
                              std::span<const GlobalTerm> reference) {
    ProbeError e;
    const std::size_t n = std::min(estimate.size(), reference.size());
    if (n == 0)
        return e;
    for (std::size_t i = 0; i < n; ++i) {
        const GlobalTerm& a = estimate[i];
        const GlobalTerm& b = reference[i];
        e.maeV += std::abs(double(a.V) - double(b.V));
        for (int c = 0; c < 3; ++c)
            e.maeT_s += std::abs(double(a.T_s[c]) - double(b.T_s[c])) / 3.0;
        e.biasN += double(a.n) - double(b.n);
        e.meanNRef += double(b.n);
    }
    const double inv = 1.0 / double(n);
    e.maeV *= inv;
    e.maeT_s *= inv;
    e.biasN *= inv;
    e.meanNRef *= inv;
    return e;
}

std::vector<GlobalTerm> evaluateGlobalTerm(const GlobalTermModel& model, const Light& light,
                                           std::span<const GlobalTermQuery> points) {
    std::vector<GlobalTerm> out(points.size());
    model.forLight(light)->evaluate(points, out);
    return out;
}

} // namespace hairvox
