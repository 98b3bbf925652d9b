// hairvox core: working storage a function reuses from call to call on the
// same thread.
//
// The shading path calls its global-term models once per batch of up to
// 1,024 points (the rasterizer's kShadeBatch), and each call needs arrays of
// that size (the queries, the samples along the fibers, the shadow segments:
// tens of KB each). Made afresh per call they are an allocation, a
// value-initialising write of every element and, whenever the allocator hands
// out memory not used before, page faults. Kept per thread, the arrays keep their capacity: after
// the first batches a call neither allocates nor writes what it does not use (the default scene A/B
// 0.918, docs/DESIGN.md).
//
// A thread can enter the same function again before the first call returns:
// the global term runs its own parallel loops, and a thread waiting in one may
// take another task of an enclosing loop ("Work Isolation" in oneTBB's
// documentation) unless the caller isolated it, as the rasterizer does
// (render/src/rasterizer.cpp, shadeBatch). Such a call finds the thread's
// storage in use and gets storage of its own, so no caller has to know.
#pragma once

#include <memory>

namespace hairvox {

/// This thread's instance of T, or a new one while that is in use. T is
/// normally a struct of vectors local to the one function that uses it (so
/// that each function has its own per-thread storage); its contents are
/// whatever the previous call on the thread left, and a call resizes and
/// overwrites what it reads.
template <typename T>
class ThreadScratch {
public:
    ThreadScratch()
        : slot_(threadSlot()) {
        if (slot_.inUse)
            own_ = std::make_unique<T>();
        else
            slot_.inUse = true;
    }
    ~ThreadScratch() {
        if (!own_)
            slot_.inUse = false;
    }
    ThreadScratch(const ThreadScratch&) = delete;
    ThreadScratch& operator=(const ThreadScratch&) = delete;

    T& operator*() { return own_ ? *own_ : slot_.value; }
    T* operator->() { return &**this; }
    /// Whether this call got storage of its own (the thread's was in use).
    bool reentered() const { return own_ != nullptr; }

private:
    struct Slot {
        T value{};
        bool inUse = false;
    };
    static Slot& threadSlot() {
        thread_local Slot slot;
        return slot;
    }
    Slot& slot_;
    std::unique_ptr<T> own_;
};

} // namespace hairvox
