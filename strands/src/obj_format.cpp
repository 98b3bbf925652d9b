// OBJ polylines: `v x y z [w]` vertices and `l i j k ...` polylines (1-based
// indices, negative indices relative to the vertices read so far, `i/t` forms
// accepted). Each `l` record is a strand, except that a record whose first
// vertex is the previous record's last vertex continues that strand: exporters
// such as Blender write one `l` record per edge. Other records are ignored
// (faces are counted in a warning).
#include "file_bytes.h"

#include <hairvox/strands/groom_io.h>

#include <charconv>
#include <string_view>

namespace hairvox {

namespace {

bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

/// Splits off the next whitespace-separated token; empty at the end of the line.
std::string_view nextToken(std::string_view& line) {
    std::size_t b = 0;
    while (b < line.size() && isSpace(line[b]))
        ++b;
    std::size_t e = b;
    while (e < line.size() && !isSpace(line[e]))
        ++e;
    const std::string_view token = line.substr(b, e - b);
    line.remove_prefix(e);
    return token;
}

class ObjParser {
public:
    ObjParser(const std::string& name, const GroomReadOptions& options)
        : name_(name), options_(options) {}

    void parseLine(std::string_view line, std::uint64_t lineNumber) {
        lineNumber_ = lineNumber;
        const std::string_view keyword = nextToken(line);
        if (keyword.empty() || keyword.front() == '#')
            return;
        if (keyword == "v")
            parseVertex(line);
        else if (keyword == "l")
            parsePolyline(line);
        else if (keyword == "f")
            ++faces_;
        else if (keyword != "vt" && keyword != "vn" && keyword != "vp" && keyword != "o" &&
                 keyword != "g" && keyword != "s" && keyword != "mtllib" && keyword != "usemtl")
            ++unknown_;
    }

    LoadedGroom finish() {
        flushStrand();
        if (groom_.empty() && !sawPolyline_)
            throw InputError(strCat(name_, ": contains no polylines ('l' records)"));
        LoadedGroom loaded;
        loaded.format = GroomFormat::Obj;
        loaded.groom = std::move(groom_);
        if (faces_ > 0)
            loaded.warnings.push_back(strCat("ignored ", faces_, " face record(s)"));
        if (unknown_ > 0)
            loaded.warnings.push_back(strCat("ignored ", unknown_, " unknown record(s)"));
        return loaded;
    }

private:
    [[noreturn]] void fail(const std::string& what) const {
        throw InputError(strCat(name_, ":", lineNumber_, ": ", what));
    }

    float parseFloat(std::string_view token) const {
        float value = 0;
        const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
        if (ec != std::errc() || end != token.data() + token.size())
            fail(strCat("'", token, "' is not a number"));
        return value;
    }

    void parseVertex(std::string_view rest) {
        Vec3f p;
        for (int axis = 0; axis < 3; ++axis) {
            const std::string_view token = nextToken(rest);
            if (token.empty())
                fail("vertex needs 3 coordinates");
            p[axis] = parseFloat(token);
        }
        if (vertices_.size() >= options_.maxPoints)
            fail(strCat("more than ", options_.maxPoints, " vertices"));
        vertices_.push_back(p);
    }

    std::uint64_t parseIndex(std::string_view token) const {
        token = token.substr(0, token.find('/'));
        long long index = 0;
        const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), index);
        if (ec != std::errc() || end != token.data() + token.size() || index == 0)
            fail(strCat("'", token, "' is not a vertex index"));
        const auto count = static_cast<long long>(vertices_.size());
        const long long resolved = index > 0 ? index - 1 : count + index;
        if (resolved < 0 || resolved >= count)
            fail(strCat("vertex index ", index, " is out of range (", count,
                        " vertices so far)"));
        return static_cast<std::uint64_t>(resolved);
    }

    void parsePolyline(std::string_view rest) {
        sawPolyline_ = true;
        std::vector<std::uint64_t> indices;
        for (std::string_view token = nextToken(rest); !token.empty(); token = nextToken(rest))
            indices.push_back(parseIndex(token));
        if (indices.size() < 2)
            fail("a polyline needs at least 2 vertices");
        const bool continues = !current_.empty() && indices.front() == lastIndex_;
        if (!continues)
            flushStrand();
        for (std::size_t i = continues ? 1 : 0; i < indices.size(); ++i)
            current_.push_back(vertices_[indices[i]]);
        lastIndex_ = indices.back();
        if (groom_.pointCount() + current_.size() > options_.maxPoints)
            fail(strCat("more than ", options_.maxPoints, " strand points"));
    }

    void flushStrand() {
        if (!current_.empty())
            groom_.addStrand(current_);
        current_.clear();
    }

    const std::string& name_;
    const GroomReadOptions& options_;
    std::uint64_t lineNumber_ = 0;
    std::vector<Vec3f> vertices_;
    std::vector<Vec3f> current_;
    std::uint64_t lastIndex_ = 0;
    Groom groom_;
    std::uint64_t faces_ = 0, unknown_ = 0;
    bool sawPolyline_ = false;
};

} // namespace

LoadedGroom readObjFile(const std::filesystem::path& path, const GroomReadOptions& options) {
    // A vertex record is at least 8 bytes ("v 0 0 0\n"): the point limit bounds the file.
    const std::vector<unsigned char> bytes = detail::readFileBytes(path, 64 * options.maxPoints);
    return parseObjBytes(bytes, path.string(), options);
}

LoadedGroom parseObjBytes(std::span<const unsigned char> bytes, const std::string& name,
                          const GroomReadOptions& options) {
    const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    if (text.find('\0') != std::string_view::npos)
        throw InputError(strCat(name, ": not an OBJ text file (contains NUL bytes)"));

    ObjParser parser(name, options);
    std::uint64_t lineNumber = 0;
    for (std::size_t pos = 0; pos < text.size();) {
        std::size_t end = text.find('\n', pos);
        if (end == std::string_view::npos)
            end = text.size();
        parser.parseLine(text.substr(pos, end - pos), ++lineNumber);
        pos = end + 1;
    }
    LoadedGroom loaded = parser.finish();
    loaded.sanitized = sanitizeGroom(loaded.groom, name);
    return loaded;
}

} // namespace hairvox
