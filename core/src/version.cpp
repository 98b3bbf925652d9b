#include <hairvox/core/version.h>

namespace hairvox {

const char* version() { return HAIRVOX_VERSION; }

} // namespace hairvox
