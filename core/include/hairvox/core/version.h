// hairvox core: the version of this build (CMake's project version), recorded
// in outputs (.vdb metadata, EXR attributes) and printed by `hairvox --version`.
#pragma once

namespace hairvox {

const char* version();

} // namespace hairvox
