#include <hairvox/core/parallel.h>

#if defined(__SSE__)
#include <xmmintrin.h>
#endif

#include <tbb/global_control.h>

#include <cstddef>
#include <optional>

namespace hairvox {

struct ThreadLimit::Impl {
    std::optional<tbb::global_control> control;
};

ThreadLimit::ThreadLimit(int threads) : impl_(std::make_unique<Impl>()) {
    if (threads > 0)
        impl_->control.emplace(tbb::global_control::max_allowed_parallelism,
                               static_cast<std::size_t>(threads));
}

ThreadLimit::~ThreadLimit() = default;

void flushDenormalsToZero() {
#if defined(__SSE__)
    constexpr unsigned kFlushToZero = 0x8000, kDenormalsAreZero = 0x0040;
    _mm_setcsr(_mm_getcsr() | kFlushToZero | kDenormalsAreZero);
#endif
}

int activeThreadCount() {
    return static_cast<int>(
        tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
}

} // namespace hairvox
