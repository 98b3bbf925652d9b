// hairvox core: the error a user can fix.
//
// InputError means bad input from outside the program (a file, a JSON field, a
// command-line option); its message names the file or field and what is wrong.
// The CLI maps it to exit code 2. Any other exception is a bug (exit code 1).
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace hairvox {

class InputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// A long operation was interrupted by the user (Ctrl-C); the CLI prints the
/// message and exits with 130.
class Interrupted : public std::runtime_error {
public:
    Interrupted() : std::runtime_error("interrupted; no partial output was written") {}
    explicit Interrupted(const std::string& message) : std::runtime_error(message) {}
};

/// Concatenates anything printable into a string: strCat("file ", name, ": ", count).
template <typename... Args>
std::string strCat(Args&&... args) {
    std::ostringstream os;
    (os << ... << std::forward<Args>(args));
    return os.str();
}

} // namespace hairvox
