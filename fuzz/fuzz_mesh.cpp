// libFuzzer target: the OBJ mesh reader, parseObjMesh() (geometry/triangle_mesh.h).
// Oracle: it returns a mesh whose every index names a vertex, whose positions
// are finite and which has at least one triangle — or throws InputError.
// Anything else (a crash, a sanitizer report, another exception) is a finding.
#include <hairvox/core/error.h>
#include <hairvox/geometry/triangle_mesh.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        const hairvox::LoadedMesh m = hairvox::parseObjMesh(
            std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.obj");
        if (m.mesh.triangles.empty())
            std::abort();
        for (const auto& t : m.mesh.triangles)
            for (const std::uint32_t v : t)
                if (v >= m.mesh.positions.size())
                    std::abort();
        for (const hairvox::Vec3f& p : m.mesh.positions)
            if (!hairvox::isFinite(p))
                std::abort();
        if (!m.mesh.cornerNormals.empty() && m.mesh.cornerNormals.size() != 3 * m.mesh.triangles.size())
            std::abort();
    } catch (const hairvox::InputError&) {
    }
    return 0;
}
