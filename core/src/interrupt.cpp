#include <hairvox/core/error.h>
#include <hairvox/core/interrupt.h>

#include <atomic>
#include <csignal>

namespace hairvox {

namespace {

// A lock-free atomic is async-signal-safe to store from a handler.
std::atomic<bool> gInterrupt{false};
static_assert(std::atomic<bool>::is_always_lock_free);

extern "C" void onInterruptSignal(int signal) {
    if (signal == SIGINT && gInterrupt.load(std::memory_order_relaxed)) {
        // Second Ctrl-C: the user insists. Default action terminates.
        std::signal(SIGINT, SIG_DFL);
        std::raise(SIGINT);
        return;
    }
    gInterrupt.store(true, std::memory_order_relaxed);
}

} // namespace

void requestInterrupt() noexcept { gInterrupt.store(true, std::memory_order_relaxed); }
bool interruptRequested() noexcept { return gInterrupt.load(std::memory_order_relaxed); }
void clearInterrupt() noexcept { gInterrupt.store(false, std::memory_order_relaxed); }

void throwIfInterrupted() {
    if (interruptRequested())
        throw Interrupted();
}

void installInterruptHandler() {
    struct sigaction action {};
    action.sa_handler = onInterruptSignal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = 0;
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
}

} // namespace hairvox
