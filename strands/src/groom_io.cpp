#include <hairvox/core/error.h>
#include <hairvox/strands/groom_io.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <fstream>

namespace hairvox {

LoadedGroom readGroom(const std::filesystem::path& path, const GroomReadOptions& options) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });

    // The .hair magic wins over the extension; otherwise the extension decides.
    char magic[4] = {};
    {
        std::ifstream in(path, std::ios::binary);
        if (!in)
            throw InputError(strCat(path.string(), ": cannot open (no such file?)"));
        in.read(magic, sizeof(magic));
    }
    if (std::memcmp(magic, "HAIR", 4) == 0 || ext == ".hair")
        return readHairFile(path, options);
    if (ext == ".tfx")
        return readTfxFile(path, options);
    if (ext == ".obj")
        return readObjFile(path, options);
    throw InputError(
        strCat(path.string(), ": unknown groom format (expected a .hair, .tfx or .obj file)"));
}

} // namespace hairvox
