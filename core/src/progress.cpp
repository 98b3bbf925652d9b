#include <hairvox/core/progress.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <unistd.h>

namespace hairvox {

bool stderrIsTerminal() { return ::isatty(STDERR_FILENO) == 1; }

ProgressReporter::ProgressReporter(std::string title, std::uint64_t totalWork, bool enabled)
    : title_(std::move(title)), total_(std::max<std::uint64_t>(totalWork, 1)), enabled_(enabled) {
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

void ProgressReporter::draw(bool final) const {
    constexpr int barWidth = 40;
    const std::uint64_t done = std::min(done_.load(std::memory_order_relaxed), total_);
    const double fraction = static_cast<double>(done) / static_cast<double>(total_);
    const int filled = static_cast<int>(fraction * barWidth);
    char bar[barWidth + 1];
    for (int i = 0; i < barWidth; ++i)
        bar[i] = i < filled ? '=' : (i == filled ? '>' : ' ');
    bar[barWidth] = '\0';
    std::fprintf(stderr, "\r%-14s [%s] %5.1f%%%s", title_.c_str(), bar, 100.0 * fraction,
                 final ? "\n" : "");
    std::fflush(stderr);
}

} // namespace hairvox
