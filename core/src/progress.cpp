#include <hairvox/core/progress.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <unistd.h>

namespace hairvox {

bool stderrIsTerminal() { return ::isatty(STDERR_FILENO) == 1; }

ProgressReporter::ProgressReporter(std::string title, std::uint64_t totalWork, bool enabled)
    : title_(std::move(title)), total_(std::max<std::uint64_t>(totalWork, 1)), enabled_(enabled),
      start_(std::chrono::steady_clock::now()) {
    if (!enabled_)
        return;
    thread_ = std::thread([this] {
        // Redraw quickly at first, then back off so that long runs cost nothing.
        auto interval = std::chrono::milliseconds(50);
        std::unique_lock lock(mutex_);
        while (!finished_) {
            wake_.wait_for(lock, interval, [this] { return finished_; });
            if (!finished_)
                draw(false);
            interval = std::min(interval * 2, std::chrono::milliseconds(500));
        }
    });
}

ProgressReporter::~ProgressReporter() { finish(); }

void ProgressReporter::finish() {
    if (!enabled_)
        return;
    {
        std::lock_guard lock(mutex_);
        if (finished_)
            return;
        finished_ = true;
    }
    wake_.notify_all();
    thread_.join();
    draw(true);
}

void ProgressReporter::limitTime(double seconds) { timeLimit_ = seconds; }

namespace {

/// "42s", "3m05s", "2h07m".
std::string duration(double seconds) {
    const auto s = static_cast<long long>(std::max(0.0, seconds) + 0.5);
    char buf[32];
    if (s < 60)
        std::snprintf(buf, sizeof(buf), "%llds", s);
    else if (s < 3600)
        std::snprintf(buf, sizeof(buf), "%lldm%02llds", s / 60, s % 60);
    else
        std::snprintf(buf, sizeof(buf), "%lldh%02lldm", s / 3600, (s % 3600) / 60);
    return buf;
}

} // namespace

void ProgressReporter::draw(bool final) const {
    constexpr int barWidth = 40;
    const std::uint64_t done = std::min(done_.load(std::memory_order_relaxed), total_);
    const double fraction = static_cast<double>(done) / static_cast<double>(total_);
    const int filled = static_cast<int>(fraction * barWidth);
    char bar[barWidth + 1];
    for (int i = 0; i < barWidth; ++i)
        bar[i] = i < filled ? '=' : (i == filled ? '>' : ' ');
    bar[barWidth] = '\0';
    // Time so far, then (while running) the estimate of what is left: the rate
    // so far over the work left, capped by the time limit if there is one.
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    std::string time = duration(elapsed);
    if (!final && done > 0) {
        double left = elapsed * (1.0 - fraction) / fraction;
        if (const double limit = timeLimit_.load(); limit > 0)
            left = std::min(left, limit - elapsed);
        time += ", ETA " + duration(left);
    }
    std::fprintf(stderr, "\r%-14s [%s] %5.1f%% %-22s%s", title_.c_str(), bar, 100.0 * fraction,
                 time.c_str(), final ? "\n" : "");
    std::fflush(stderr);
}

} // namespace hairvox
