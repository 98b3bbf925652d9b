#include <hairvox/core/thread_scratch.h>

#include <gtest/gtest.h>

#include <thread>
#include <vector>

namespace hairvox {
namespace {

struct Storage {
    std::vector<int> values;
};

/// What a function using the scratch sees: the storage it got, and whether
/// that was the thread's own.
struct Call {
    const Storage* storage;
    bool reentered;
};

Call useScratch() {
    ThreadScratch<Storage> scratch;
    scratch->values.resize(1000);
    return {&*scratch, scratch.reentered()};
}

TEST(ThreadScratch, ACallReusesTheStorageOfTheCallBeforeOnItsThread) {
    const Call first = useScratch();
    const Call second = useScratch();
    EXPECT_FALSE(first.reentered);
    EXPECT_FALSE(second.reentered);
    EXPECT_EQ(first.storage, second.storage);
    // Its capacity is kept: the next call on the thread does not allocate.
    ThreadScratch<Storage> scratch;
    EXPECT_GE(scratch->values.capacity(), 1000u);
}

TEST(ThreadScratch, ACallMadeWhileTheThreadsStorageIsInUseGetsItsOwn) {
    // As when a thread waiting in a parallel loop inside the function takes
    // another call's task: the inner call must not write the outer's arrays.
    ThreadScratch<Storage> outer;
    outer->values.assign(4, 7);
    {
        ThreadScratch<Storage> nested;
        EXPECT_TRUE(nested.reentered());
        EXPECT_NE(&*nested, &*outer);
        nested->values.assign(4, -1);
    }
    EXPECT_FALSE(outer.reentered());
    EXPECT_EQ(outer->values, std::vector<int>(4, 7));
}

TEST(ThreadScratch, TheThreadsStorageIsFreeAgainAfterANestedCall) {
    const Storage* own = nullptr;
    {
        ThreadScratch<Storage> outer;
        own = &*outer;
        ThreadScratch<Storage> nested;
        EXPECT_TRUE(nested.reentered());
    }
    const Call after = useScratch();
    EXPECT_FALSE(after.reentered);
    EXPECT_EQ(after.storage, own);
}

TEST(ThreadScratch, ThreadsHaveTheirOwnStorage) {
    const Call here = useScratch();
    Call there{};
    std::thread([&] { there = useScratch(); }).join();
    EXPECT_FALSE(there.reentered);
    EXPECT_NE(here.storage, there.storage);
}

} // namespace
} // namespace hairvox
