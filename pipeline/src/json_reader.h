// hairvox pipeline (private): typed, path-aware reading of a JSON document.
//
// Every accessor checks the type and range of one value and throws an
// InputError that names the source, the JSON pointer of the value (RFC 6901)
// and what was expected, e.g.
//   scene.json: /lights/1/intensity: expected a number in [0, 1e+06], got "bright"
// JsonObject remembers which keys were asked for; finish() rejects the others,
// so that a typo in a key is an error rather than a silently ignored setting.
#pragma once

#include <hairvox/core/enum_names.h>
#include <hairvox/core/rgb.h>
#include <hairvox/core/vecmath.h>

#include <nlohmann/json.hpp>

#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

namespace hairvox::json {

/// A closed interval [lo, hi]; an infinite bound is printed as ">= lo" / "<= hi".
/// `openLo` makes the lower bound exclusive ("> lo").
struct Range {
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
    bool openLo = false;

    bool contains(double x) const { return (openLo ? x > lo : x >= lo) && x <= hi; }
    std::string describe() const; ///< "in [0, 1]", ">= 0", "in (0, 1000]"
};

class JsonObject;

/// One value of the document (or the absence of an optional key) and its path.
class JsonValue {
public:
    JsonValue(const nlohmann::json* value, std::string path, const std::string& source)
        : value_(value)
        , path_(std::move(path))
        , source_(&source) {}

    bool present() const { return value_ != nullptr; }
    bool isNull() const { return value_ != nullptr && value_->is_null(); }
    bool isString() const { return value_ != nullptr && value_->is_string(); }
    bool isNumber() const { return value_ != nullptr && value_->is_number(); }
    const std::string& path() const { return path_; }

    /// "<source>: <path>: expected <what>, got <value>".
    [[noreturn]] void failExpected(std::string_view what) const;
    /// "<source>: <path>: <message>".
    [[noreturn]] void fail(std::string_view message) const;

    double number(const Range& range) const;
    float numberF(const Range& range) const;
    /// An integer (a JSON float with an integral value is accepted too).
    std::uint64_t integer(std::uint64_t lo, std::uint64_t hi) const;
    bool boolean() const;
    std::string string() const;
    /// One of `choices`; the error lists them.
    std::string oneOf(const std::vector<std::string>& choices) const;
    /// One of an enum's names (core/enum_names.h), as its value.
    template <typename E, std::size_t N>
    E oneOf(const EnumNames<E, N>& names) const {
        return *names.parse(oneOf(names.names()));
    }
    /// An array of exactly 3 numbers, each in `range`.
    Vec3f vec3(const Range& range) const;
    Rgb rgb(const Range& range) const;
    /// An array of `minSize`..`maxSize` elements.
    std::vector<JsonValue> array(std::size_t minSize, std::size_t maxSize) const;
    JsonObject object() const;

private:
    void requirePresent(std::string_view what) const;

    const nlohmann::json* value_;
    std::string path_;
    const std::string* source_;
};

class JsonObject {
public:
    JsonObject(const nlohmann::json& value, std::string path, const std::string& source)
        : value_(&value)
        , path_(std::move(path))
        , source_(&source) {}

    /// The value under `key`; absent (present() == false) if the key is missing.
    JsonValue operator[](std::string_view key);
    /// Throws "missing" if absent.
    JsonValue required(std::string_view key, std::string_view what);
    bool has(std::string_view key) const { return value_->contains(key); }
    const std::string& path() const { return path_; }

    /// Throws for the first key that was never asked for, listing the valid keys.
    void finish() const;
    /// "<source>: <path of the object>: <message>".
    [[noreturn]] void fail(std::string_view message) const;

private:
    const nlohmann::json* value_;
    std::string path_;
    const std::string* source_;
    std::vector<std::string> known_;
};

/// Appends one reference token to a JSON pointer ("~" → "~0", "/" → "~1").
std::string childPath(const std::string& parent, std::string_view token);

} // namespace hairvox::json
