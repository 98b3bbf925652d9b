#include <hairvox/core/progress.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <unistd.h>
#include <utility>
#include <vector>

namespace hairvox {

namespace {

/// The live reporters in creation order, each with its serial number, for
/// currentProgress(). A reporter is removed (under the mutex) before it is
/// destroyed, so what the list points to is alive while the mutex is held.
struct Registry {
    std::mutex mutex;
    std::vector<std::pair<const ProgressReporter*, std::uint64_t>> live;
    std::uint64_t serial = 0;

    static Registry& get() {
        static Registry registry;
        return registry;
    }
    void add(const ProgressReporter* r) {
        std::lock_guard lock(mutex);
        live.emplace_back(r, ++serial);
    }
    void remove(const ProgressReporter* r) {
        std::lock_guard lock(mutex);
        std::erase_if(live, [r](const auto& entry) { return entry.first == r; });
    }
};

} // namespace

bool stderrIsTerminal() { return ::isatty(STDERR_FILENO) == 1; }

std::optional<ProgressSnapshot> currentProgress() {
    Registry& registry = Registry::get();
    std::lock_guard lock(registry.mutex);
    if (registry.live.empty())
        return std::nullopt;
    const auto& [reporter, serial] = registry.live.back();
    return ProgressSnapshot{reporter->title(), reporter->done(), reporter->total(), serial};
}

ProgressReporter::ProgressReporter(std::string title, std::uint64_t totalWork, bool enabled)
    : title_(std::move(title)), total_(std::max<std::uint64_t>(totalWork, 1)), enabled_(enabled),
      start_(std::chrono::steady_clock::now()) {
    Registry::get().add(this);
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

std::uint64_t ProgressReporter::done() const {
    return std::min(done_.load(std::memory_order_relaxed), total_);
}

void ProgressReporter::finish() {
    Registry::get().remove(this); // idempotent
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
    const std::uint64_t work = done();
    const double fraction = static_cast<double>(work) / static_cast<double>(total_);
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
    if (!final && work > 0) {
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
