#include <hairvox/core/error.h>
#include <hairvox/strands/fiber_scale.h>

namespace hairvox {

void FiberScale::validate() const {
    if (!(diameter > 0 && diameter <= 1000))
        throw InputError(strCat("fiber.diameter = ", diameter, ": expected a number in (0, 1000]"));
    if (!(densityMultiplier >= 0.01f && densityMultiplier <= 10000))
        throw InputError(strCat("fiber.density_multiplier = ", densityMultiplier,
                                ": expected a number in [0.01, 10000]"));
}

void FiberScale::hashInto(Hasher& hasher) const {
    hasher.value(diameter).value(densityMultiplier);
}

std::ostream& operator<<(std::ostream& os, const FiberScale& s) {
    return os << "FiberScale(D=" << s.diameter << ", k=" << s.densityMultiplier << ")";
}

} // namespace hairvox
