#include "json_reader.h"

#include <hairvox/core/error.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace hairvox::json {

namespace {

/// A short description of a value for error messages. Containers are described
/// by their size only (never dumped: the document may be deeply nested).
std::string describeValue(const nlohmann::json& v) {
    switch (v.type()) {
    case nlohmann::json::value_t::object:
        return "an object";
    case nlohmann::json::value_t::array:
        return strCat("an array of ", v.size(), " elements");
    case nlohmann::json::value_t::string: {
        std::string s = v.dump();
        constexpr std::size_t maxChars = 48;
        if (s.size() > maxChars)
            s = s.substr(0, maxChars) + "...\"";
        return s;
    }
    default:
        return v.dump();
    }
}

std::string formatBound(double x) {
    std::ostringstream os;
    os << x;
    return os.str();
}

} // namespace

std::string Range::describe() const {
    const bool hasLo = std::isfinite(lo), hasHi = std::isfinite(hi);
    if (hasLo && hasHi)
        return strCat("in ", openLo ? "(" : "[", formatBound(lo), ", ", formatBound(hi), "]");
    if (hasLo)
        return strCat(openLo ? "> " : ">= ", formatBound(lo));
    if (hasHi)
        return strCat("<= ", formatBound(hi));
    return "finite";
}

std::string childPath(const std::string& parent, std::string_view token) {
    std::string out = parent;
    out += '/';
    for (char c : token) {
        if (c == '~')
            out += "~0";
        else if (c == '/')
            out += "~1";
        else
            out += c;
    }
    return out;
}

void JsonValue::failExpected(std::string_view what) const {
    if (value_ == nullptr)
        fail(strCat("missing (expected ", what, ")"));
    fail(strCat("expected ", what, ", got ", describeValue(*value_)));
}

void JsonValue::fail(std::string_view message) const {
    throw InputError(strCat(*source_, ": ", path_.empty() ? "/" : path_, ": ", message));
}

void JsonValue::requirePresent(std::string_view what) const {
    if (value_ == nullptr)
        failExpected(what);
}

double JsonValue::number(const Range& range) const {
    const std::string what = strCat("a number ", range.describe());
    requirePresent(what);
    if (!value_->is_number())
        failExpected(what);
    const double x = value_->get<double>();
    if (!std::isfinite(x) || !range.contains(x))
        failExpected(what);
    return x;
}

float JsonValue::numberF(const Range& range) const {
    const double x = number(range);
    if (!std::isfinite(static_cast<float>(x)))
        failExpected(strCat("a number ", range.describe(), " within single precision"));
    return static_cast<float>(x);
}

std::uint64_t JsonValue::integer(std::uint64_t lo, std::uint64_t hi) const {
    const std::string what = strCat("an integer in [", lo, ", ", hi, "]");
    requirePresent(what);
    if (value_->is_number_unsigned()) {
        const auto x = value_->get<std::uint64_t>();
        if (x >= lo && x <= hi)
            return x;
    } else if (value_->is_number_integer()) {
        const auto x = value_->get<std::int64_t>();
        if (x >= 0 && std::uint64_t(x) >= lo && std::uint64_t(x) <= hi)
            return std::uint64_t(x);
    } else if (value_->is_number_float()) {
        // 2e4 is a fine way to write 20000. double(hi) rounds up to 2^64 for
        // hi = 2^64 - 1, and converting 2^64 is undefined: compare as integers.
        const double x = value_->get<double>();
        if (x == std::floor(x) && x >= 0 && x < 0x1p64) {
            const auto n = static_cast<std::uint64_t>(x);
            if (n >= lo && n <= hi)
                return n;
        }
    }
    failExpected(what);
}

bool JsonValue::boolean() const {
    requirePresent("true or false");
    if (!value_->is_boolean())
        failExpected("true or false");
    return value_->get<bool>();
}

std::string JsonValue::string() const {
    requirePresent("a string");
    if (!value_->is_string())
        failExpected("a string");
    return value_->get<std::string>();
}

std::string JsonValue::oneOf(const std::vector<std::string>& choices) const {
    std::string what = "one of ";
    for (auto it = choices.begin(); it != choices.end(); ++it)
        what += strCat(it == choices.begin() ? "\"" : ", \"", *it, "\"");
    requirePresent(what);
    if (value_->is_string()) {
        const auto& s = value_->get_ref<const std::string&>();
        if (std::find(choices.begin(), choices.end(), s) != choices.end())
            return s;
    }
    failExpected(what);
}

Vec3f JsonValue::vec3(const Range& range) const {
    const std::string what = strCat("an array of 3 numbers, each ", range.describe());
    requirePresent(what);
    if (!value_->is_array() || value_->size() != 3)
        failExpected(what);
    Vec3f v;
    for (int c = 0; c < 3; ++c)
        v[c] = JsonValue(&(*value_)[std::size_t(c)], childPath(path_, std::to_string(c)), *source_)
                   .numberF(range);
    return v;
}

Rgb JsonValue::rgb(const Range& range) const {
    const Vec3f v = vec3(range);
    return {v.x, v.y, v.z};
}

std::vector<JsonValue> JsonValue::array(std::size_t minSize, std::size_t maxSize) const {
    const std::string what = minSize == maxSize
                                 ? strCat("an array of ", minSize, " elements")
                                 : strCat("an array of ", minSize, " to ", maxSize, " elements");
    requirePresent(what);
    if (!value_->is_array() || value_->size() < minSize || value_->size() > maxSize)
        failExpected(what);
    std::vector<JsonValue> out;
    out.reserve(value_->size());
    for (std::size_t i = 0; i < value_->size(); ++i)
        out.emplace_back(&(*value_)[i], childPath(path_, std::to_string(i)), *source_);
    return out;
}

JsonObject JsonValue::object() const {
    requirePresent("an object");
    if (!value_->is_object())
        failExpected("an object");
    return JsonObject(*value_, path_, *source_);
}

JsonValue JsonObject::operator[](std::string_view key) {
    if (std::find(known_.begin(), known_.end(), key) == known_.end())
        known_.emplace_back(key);
    const auto it = value_->find(key);
    return JsonValue(it == value_->end() ? nullptr : &*it, childPath(path_, key), *source_);
}

JsonValue JsonObject::required(std::string_view key, std::string_view what) {
    JsonValue v = (*this)[key];
    if (!v.present())
        v.failExpected(what);
    return v;
}

void JsonObject::fail(std::string_view message) const {
    JsonValue(value_, path_, *source_).fail(message);
}

void JsonObject::finish() const {
    for (const auto& [key, value] : value_->items()) {
        if (std::find(known_.begin(), known_.end(), key) != known_.end())
            continue;
        std::string valid;
        for (const std::string& k : known_)
            valid += strCat(valid.empty() ? "" : ", ", k);
        throw InputError(strCat(*source_, ": ", childPath(path_, key), ": unknown key (valid keys",
                                path_.empty() ? "" : strCat(" in ", path_), ": ", valid, ")"));
    }
}

} // namespace hairvox::json
