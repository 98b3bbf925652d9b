// hairvox reliability tests: run the hairvox executable as a child process
// that the test can time, bound (address space, wall time) and signal.
//
// Output (stdout and stderr together) goes to a file in the working directory,
// so a chatty child never blocks on a full pipe.
#pragma once

#include "test_util.h"

#include <sys/resource.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace hairvox::test {

/// True when this binary (and so the hairvox it tests) runs under a sanitizer
/// that reserves terabytes of address space: RLIMIT_AS cannot bound it.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__) // GCC
inline constexpr bool kSanitizedBuild = true;
#elif defined(__has_feature)                                         // Clang
inline constexpr bool kSanitizedBuild =
    __has_feature(address_sanitizer) || __has_feature(thread_sanitizer);
#else
inline constexpr bool kSanitizedBuild = false;
#endif

struct ChildOptions {
    std::vector<std::string> args;             ///< after the executable name
    std::filesystem::path workDir;             ///< also holds the output file
    std::vector<std::string> env;              ///< "KEY=VALUE" set or replaced in the child
    std::optional<std::uint64_t> addressSpace; ///< RLIMIT_AS in bytes (ignored when sanitized)
};

struct ChildResult {
    bool exited = false;   ///< normal exit (exitCode valid)
    int exitCode = -1;
    int signal = 0;        ///< the signal that ended it, if any
    bool timedOut = false; ///< killed by wait() after its time limit
    double seconds = 0;    ///< from start to exit
    std::string output;
};

using Clock = std::chrono::steady_clock;

/// A running hairvox process; the destructor kills it if still running.
class Child {
public:
    explicit Child(const ChildOptions& options)
        : outputPath_(options.workDir / "child-output.txt") {
        // Everything the child needs is built before fork(): after it, only
        // async-signal-safe calls.
        std::vector<std::string> argStrings{HAIRVOX_BINARY};
        argStrings.insert(argStrings.end(), options.args.begin(), options.args.end());
        std::vector<std::string> envStrings = mergedEnvironment(options.env);
        std::vector<char*> argv = pointers(argStrings), envp = pointers(envStrings);
        const std::string workDir = options.workDir.string(), output = outputPath_.string();
        rlimit limit{};
        const bool limitMemory = options.addressSpace && !kSanitizedBuild;
        if (limitMemory)
            limit.rlim_cur = limit.rlim_max = *options.addressSpace;

        start_ = Clock::now();
        pid_ = ::fork();
        if (pid_ < 0)
            throw std::runtime_error("fork failed");
        if (pid_ == 0) {
            const int fd = ::open(output.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
            if (fd < 0 || ::chdir(workDir.c_str()) != 0 || ::dup2(fd, 1) < 0 || ::dup2(fd, 2) < 0)
                ::_exit(126);
            if (limitMemory && ::setrlimit(RLIMIT_AS, &limit) != 0)
                ::_exit(126);
            ::execve(argv[0], argv.data(), envp.data());
            ::_exit(127);
        }
    }

    ~Child() {
        if (pid_ > 0 && !reaped_) {
            ::kill(pid_, SIGKILL);
            int status = 0;
            ::waitpid(pid_, &status, 0);
        }
    }

    Child(const Child&) = delete;
    Child& operator=(const Child&) = delete;

    pid_t pid() const { return pid_; }
    double secondsRunning() const {
        return std::chrono::duration<double>(Clock::now() - start_).count();
    }

    void signal(int sig) const { ::kill(pid_, sig); }

    /// Exit status if the child has ended (reaps it), nullopt while it runs.
    std::optional<ChildResult> poll() {
        int status = 0;
        const pid_t r = ::waitpid(pid_, &status, WNOHANG);
        if (r != pid_)
            return std::nullopt;
        reaped_ = true;
        ChildResult result;
        result.seconds = secondsRunning();
        result.exited = WIFEXITED(status);
        if (result.exited)
            result.exitCode = WEXITSTATUS(status);
        if (WIFSIGNALED(status))
            result.signal = WTERMSIG(status);
        std::ifstream in(outputPath_, std::ios::binary);
        result.output.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
        return result;
    }

    /// Waits up to `seconds`; past that, kills the child and reports timedOut.
    ChildResult wait(double seconds) {
        const auto deadline = Clock::now() + std::chrono::duration<double>(seconds);
        while (Clock::now() < deadline) {
            if (std::optional<ChildResult> r = poll())
                return *r;
            std::this_thread::sleep_for(std::chrono::milliseconds(2));
        }
        signal(SIGKILL);
        std::optional<ChildResult> r;
        while (!(r = poll()))
            std::this_thread::sleep_for(std::chrono::milliseconds(2));
        r->timedOut = true;
        return *r;
    }

private:
    static std::vector<std::string> mergedEnvironment(const std::vector<std::string>& overrides) {
        std::vector<std::string> env;
        for (char** e = environ; *e != nullptr; ++e) {
            const std::string entry = *e;
            const std::string key = entry.substr(0, entry.find('=') + 1);
            bool replaced = false;
            for (const std::string& o : overrides)
                replaced = replaced || o.compare(0, key.size(), key) == 0;
            if (!replaced)
                env.push_back(entry);
        }
        env.insert(env.end(), overrides.begin(), overrides.end());
        return env;
    }

    static std::vector<char*> pointers(std::vector<std::string>& strings) {
        std::vector<char*> out;
        for (std::string& s : strings)
            out.push_back(s.data());
        out.push_back(nullptr);
        return out;
    }

    std::filesystem::path outputPath_;
    Clock::time_point start_;
    pid_t pid_ = -1;
    bool reaped_ = false;
};

/// Runs to completion (or the time limit).
inline ChildResult runChild(const ChildOptions& options, double timeoutSeconds) {
    Child child(options);
    return child.wait(timeoutSeconds);
}

inline std::string readBytes(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

} // namespace hairvox::test
