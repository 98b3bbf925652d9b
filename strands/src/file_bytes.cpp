#include "file_bytes.h"

#include <fstream>
#include <limits>

namespace hairvox::detail {

std::vector<unsigned char> readFileBytes(const std::filesystem::path& path,
                                         std::uint64_t maxBytes) {
    const std::string name = path.string();
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
        throw InputError(strCat(name, ": no such file"));
    const std::uint64_t size = std::filesystem::file_size(path, ec);
    if (ec)
        throw InputError(strCat(name, ": cannot read size: ", ec.message()));
    if (size > maxBytes)
        throw InputError(strCat(name, ": file is ", size, " bytes, more than the limit of ",
                                maxBytes, " bytes for this format"));
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw InputError(strCat(name, ": cannot open for reading"));
    std::vector<unsigned char> bytes(size);
    in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size));
    if (static_cast<std::uint64_t>(in.gcount()) != size)
        throw InputError(strCat(name, ": read error (file changed while reading?)"));
    return bytes;
}

void FileBytes::checkRange(std::uint64_t offset, std::uint64_t count, std::uint64_t elementSize,
                           const char* field) const {
    const std::uint64_t maxCount = std::numeric_limits<std::uint64_t>::max() / elementSize;
    if (count > maxCount || offset > size() || count * elementSize > size() - offset)
        throw InputError(strCat(name_, ": truncated or corrupt: ", field, " needs ",
                                count > maxCount ? std::string("an absurd number of")
                                                 : std::to_string(count * elementSize),
                                " bytes at offset ", offset, " but the file has ", size(),
                                " bytes"));
}

} // namespace hairvox::detail
