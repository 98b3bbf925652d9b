// hairvox core: storage for arrays of megabytes (the film, the projected
// strand vertices, the global term's bricks and shadow lines).
//
// What such an array costs is its pages, not its bytes (measured on
// this project's 2-core VM, docs/DESIGN.md §7):
//  - First touch. std::vector<T>::resize(n) value-initialises — for floats or
//    plain structs a memset of the new range on the calling thread — and that
//    memset is every page's fault and the kernel's zeroing of it, serially:
//    the 1080p film (357 MiB) took 0.7 s on one core before a tile was
//    drawn. A LargeVector's resize(n) default-initialises (nothing, for
//    trivial types), so the pages are first touched by the threads that fill
//    them. assign(n, v), resize(n, v) and construction from values still
//    write. The elements added by resize(n) are indeterminate: use it only
//    where every element is written before it is read (callers say where).
//  - Address translation. The renderer reads these arrays scattered (a
//    tile's strand vertices and film rows, a query's shadow lines); with
//    4 KiB pages the 32 rows of one tile in the 19 layers of a 1080p film
//    alone are some 600 pages, and under a hypervisor every TLB miss is a
//    two-level walk. Blocks of kHugePageBytes or more are therefore aligned
//    to 2 MiB and advised to the kernel as transparent huge pages (madvise
//    MADV_HUGEPAGE: used where /sys/kernel/mm/transparent_hugepage/enabled
//    says "madvise" or "always", ignored where it says "never"). What both
//    save, per scene, is in docs/DESIGN.md §7 ("Pages"). Rounding a block
//    up to 2 MiB costs at most 2 MiB per array.
// Builds that poison what is not written (HAIRVOX_POISON_UNINITIALIZED, the
// sanitizer builds) fill every new block with 0xFF bytes — NaN as floats —
// so that a read before the first write shows in the tests.
#pragma once

#include <algorithm>
#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace hairvox {

/// Blocks of at least this many bytes are backed by transparent huge pages.
inline constexpr std::size_t kHugePageBytes = std::size_t(2) << 20;

/// `bytes` of storage aligned to `alignment` (a power of two), on huge pages
/// when bytes ≥ kHugePageBytes; std::bad_alloc when there is none. Release
/// it with deallocateLarge() and the same size and alignment.
void* allocateLarge(std::size_t bytes, std::size_t alignment);
void deallocateLarge(void* p, std::size_t bytes, std::size_t alignment) noexcept;

/// The allocator of LargeVector: allocateLarge(), and construct(p) without
/// arguments default-initialises (the idiom of Boost.Container's
/// default_init_t).
template <typename T>
class LargeArrayAllocator {
public:
    using value_type = T;

    LargeArrayAllocator() noexcept = default;
    template <typename U>
    LargeArrayAllocator(const LargeArrayAllocator<U>&) noexcept {} // NOLINT: rebinding

    T* allocate(std::size_t n) {
        if (n > std::size_t(-1) / sizeof(T))
            throw std::bad_array_new_length();
        return static_cast<T*>(allocateLarge(n * sizeof(T), alignof(T)));
    }
    void deallocate(T* p, std::size_t n) noexcept { deallocateLarge(p, n * sizeof(T), alignof(T)); }

    template <typename U>
    void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
        ::new (static_cast<void*>(p)) U;
    }
    template <typename U, typename... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
};

template <typename T, typename U>
bool operator==(const LargeArrayAllocator<T>&, const LargeArrayAllocator<U>&) noexcept {
    return true;
}

/// A std::vector on huge pages whose resize(n) leaves new elements
/// default-initialised.
template <typename T>
using LargeVector = std::vector<T, LargeArrayAllocator<T>>;

/// A fixed-size array on huge pages whose elements its producer creates, for
/// element types with default member initialisers (Rgb, the global term's
/// 8-lane values): LargeVector's resize(n) runs those initialisers, a write
/// of every page on the calling thread. Here nothing is written until the
/// producer fills the elements (std::uninitialized_fill, _copy, ... from its
/// threads) before anything reads them; the sanitizer builds poison them as
/// allocateLarge() does. T is trivially copyable and destructible, so that
/// neither creating nor discarding its elements has effects to skip.
template <typename T>
class LargeBuffer {
    static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);

public:
    LargeBuffer() = default;
    explicit LargeBuffer(std::size_t n)
        : size_(n) {
        if (n > std::size_t(-1) / sizeof(T))
            throw std::bad_array_new_length();
        data_.reset(static_cast<T*>(allocateLarge(bytes(), alignof(T))));
        data_.get_deleter().bytes = bytes();
    }
    /// n copies of `value`, written on the calling thread.
    LargeBuffer(std::size_t n, const T& value)
        : LargeBuffer(n) {
        std::uninitialized_fill(begin(), end(), value);
    }
    LargeBuffer(LargeBuffer&& o) noexcept
        : data_(std::move(o.data_))
        , size_(std::exchange(o.size_, 0)) {}
    LargeBuffer& operator=(LargeBuffer&& o) noexcept {
        data_ = std::move(o.data_);
        size_ = std::exchange(o.size_, 0);
        return *this;
    }

    std::size_t size() const { return size_; }
    bool empty() const { return size_ == 0; }
    T* data() { return data_.get(); }
    const T* data() const { return data_.get(); }
    T* begin() { return data(); }
    T* end() { return data() + size_; }
    const T* begin() const { return data(); }
    const T* end() const { return data() + size_; }
    T& operator[](std::size_t i) { return data_[i]; }
    const T& operator[](std::size_t i) const { return data_[i]; }
    /// Bytes allocated (without the huge-page rounding).
    std::size_t bytes() const { return std::max<std::size_t>(size_, 1) * sizeof(T); }

private:
    struct Delete {
        std::size_t bytes; ///< (no initialiser: GCC would not see the deleter as default-constructible)
        void operator()(T* p) const noexcept { deallocateLarge(p, bytes, alignof(T)); }
    };
    std::unique_ptr<T[], Delete> data_;
    std::size_t size_ = 0;
};

} // namespace hairvox
