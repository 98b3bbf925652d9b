// hairvox core: thread-count control.
//
// Determinism rule for every parallel stage: work is split into chunks whose
// boundaries do not depend on the number of threads, and per-chunk results
// are combined in chunk order. The same input then gives the same bytes with
// 1, 2 or 64 threads.
#pragma once

#include <memory>

namespace hairvox {

/// Caps TBB's parallelism for its lifetime (the CLI's --threads; tests use 1, 2, 8).
/// `threads <= 0` leaves TBB's default (all cores).
class ThreadLimit {
public:
    explicit ThreadLimit(int threads);
    ~ThreadLimit();
    ThreadLimit(const ThreadLimit&) = delete;
    ThreadLimit& operator=(const ThreadLimit&) = delete;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// The number of threads TBB will use now.
int activeThreadCount();

/// Sets flush-to-zero and denormals-are-zero for the calling thread (the x86
/// MXCSR bits): denormal floats then cost what normal ones do. Embree asks for
/// it ("a severe performance impact" otherwise); the path tracer sets it in
/// every task, so its results do not depend on which thread ran what.
void flushDenormalsToZero();

} // namespace hairvox
