// hairvox core: progress reporting for long operations.
//
// Modelled on pbrt-v4's ProgressReporter: workers add completed work
// atomically; one background thread redraws the bar on stderr with back-off,
// with the time so far and an estimate of the time left (ETA).
// Disabled (and costing one atomic add per call) when stderr is not a terminal
// or the user asked for quiet output.
//
// A caller that cannot watch stderr (the Python module's progress callback)
// polls currentProgress() instead, from any thread: every reporter, drawn or
// not, is listed while it lives.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

namespace hairvox {

class ProgressReporter {
public:
    /// `enabled == false` draws nothing; the terminal check is done by the caller
    /// through stderrIsTerminal().
    ProgressReporter(std::string title, std::uint64_t totalWork, bool enabled);
    ~ProgressReporter();
    ProgressReporter(const ProgressReporter&) = delete;
    ProgressReporter& operator=(const ProgressReporter&) = delete;

    /// Thread-safe.
    void update(std::uint64_t work = 1) { done_.fetch_add(work, std::memory_order_relaxed); }
    /// Draws the final state and stops the redraw thread; idempotent.
    void finish();
    /// The work stops after this many seconds at the latest: the ETA never exceeds it.
    void limitTime(double seconds);

    const std::string& title() const { return title_; }
    std::uint64_t total() const { return total_; }
    /// Work done so far, at most total().
    std::uint64_t done() const;

private:
    void draw(bool final) const;

    std::string title_;
    std::uint64_t total_;
    std::atomic<std::uint64_t> done_{0};
    bool enabled_;
    std::chrono::steady_clock::time_point start_;
    std::atomic<double> timeLimit_{0.0}; // read by the redraw thread
    bool finished_ = false;
    std::mutex mutex_;
    std::condition_variable wake_;
    std::thread thread_;
};

/// What currentProgress() reads of a live reporter.
struct ProgressSnapshot {
    std::string title;
    std::uint64_t done = 0, total = 0;
    /// Differs between reporters created one after another (a new stage).
    std::uint64_t serial = 0;
};

/// The most recently created ProgressReporter that has not finished, or
/// nullopt when none is running. Thread-safe.
std::optional<ProgressSnapshot> currentProgress();

bool stderrIsTerminal();

} // namespace hairvox
