#include <hairvox/core/error.h>
#include <hairvox/core/math.h>
#include <hairvox/transmittance/crossing_table.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <stdexcept>

namespace hairvox {

namespace {

/// ā_f is clamped away from 0 so that ln ā_f stays finite for opaque fibers
/// (σ_a = 50 gives ā_f ≈ 1e-40 and below): beyond this a crossing is black anyway.
constexpr float kMinABar = 1e-30f;

} // namespace

CrossingTable CrossingTable::build(const std::function<Rgb(float theta)>& aBar_f,
                                   const std::function<Rgb(float theta)>& beta2Bar_f,
                                   int samples) {
    assert(samples >= 3);
    CrossingTable table;
    table.entries_.resize(static_cast<std::size_t>(samples));
    table.scale_ = static_cast<float>(samples - 1) / static_cast<float>(Pi);
    for (int i = 0; i < samples; ++i) {
        const float theta = std::clamp(static_cast<float>(i) / table.scale_ - static_cast<float>(PiOver2),
                                       -static_cast<float>(PiOver2), static_cast<float>(PiOver2));
        const Rgb aRaw = aBar_f(theta), beta2 = beta2Bar_f(theta);
        if (!aRaw.isFinite() || !beta2.isFinite())
            throw std::invalid_argument(strCat("CrossingTable: non-finite a_f or beta2_f at theta = ",
                                               theta, " (", aRaw, ", ", beta2, ")"));
        const Rgb a = clamp(aRaw, kMinABar, 1.0f);
        Entry& e = table.entries_[static_cast<std::size_t>(i)];
        e.values = {log(a), max(beta2, Rgb(0.0f))};
        e.oneMinusABar_f = Rgb(1.0f) - a;
    }
    // Isotropic average ½∫_{−1}^{1} rates(s) ds = ½∫ rates(sin θ) cos θ dθ, by
    // the midpoint rule in θ on a grid 16× finer than the table.
    const int steps = 16 * (samples - 1);
    const double h = Pi / steps;
    for (int i = 0; i < steps; ++i) {
        const double theta = -PiOver2 + (i + 0.5) * h;
        table.isotropic_ += table.rates(static_cast<float>(std::sin(theta))) *
                            static_cast<float>(0.5 * h * std::cos(theta));
    }
    return table;
}

CrossingTable CrossingTable::fromDualScattering(const DualScatteringTables& tables) {
    return build([&](float theta) { return tables.aBar_f(theta); },
                 [&](float theta) { return tables.beta2Bar_f(theta); });
}

std::pair<std::size_t, float> CrossingTable::locate(float s) const {
    const float x = (safeASin(std::clamp(s, -1.0f, 1.0f)) + static_cast<float>(PiOver2)) * scale_;
    const auto i = std::min(static_cast<std::size_t>(std::max(x, 0.0f)), entries_.size() - 2);
    return {i, std::clamp(x - static_cast<float>(i), 0.0f, 1.0f)};
}

CrossingTable::Values CrossingTable::crossing(float sinTheta) const {
    const auto [i, t] = locate(sinTheta);
    const Values& a = entries_[i].values;
    const Values& b = entries_[i + 1].values;
    return {lerp(t, a.logABar_f, b.logABar_f), lerp(t, a.beta2Bar_f, b.beta2Bar_f)};
}

CrossingTable::Rates CrossingTable::rates(float sinTheta) const {
    const auto [i, t] = locate(sinTheta);
    const Entry& a = entries_[i];
    const Entry& b = entries_[i + 1];
    const float cosTheta = cosFromSin(std::clamp(sinTheta, -1.0f, 1.0f));
    return {cosTheta, cosTheta * lerp(t, a.oneMinusABar_f, b.oneMinusABar_f),
            cosTheta * -lerp(t, a.values.logABar_f, b.values.logABar_f),
            cosTheta * lerp(t, a.values.beta2Bar_f, b.values.beta2Bar_f)};
}

void checkCrossingTables(const CrossingTables& tables, std::size_t fiberTypes) {
    if (tables.size() < std::max<std::size_t>(fiberTypes, 1))
        throw InputError(strCat("the groom has ", fiberTypes, " fiber type(s) but ",
                                tables.size(), " crossing table(s) were given: one per type"));
}

} // namespace hairvox
