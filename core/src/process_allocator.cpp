// hairvox programs' allocator settings: jemalloc with transparent huge pages.
//
// Linked into the executables only (the CLI and the benchmark programs, by
// hairvox_use_process_allocator() in cmake/HairvoxCompileOptions.cmake), never
// into the libraries: a program that links them chooses its own allocator.
// Builds without jemalloc (-DHAIRVOX_JEMALLOC=OFF, the sanitizer builds) keep
// glibc's malloc and do not compile this file; the images are the same bytes
// either way.
//
// Why (docs/DESIGN.md §7, "The allocator"): on the machines this renderer is
// measured on, a page's first touch is the cost — the kernel's fault and its
// zeroing, ~1.5 ns a byte on this VM (machine_bench FirstTouch). glibc's
// malloc serves its heaps in 4 KiB pages, faulted one by one: the fiber
// grid's OpenVDB leaves, when it was kept as OpenVDB grids (a 2 KB and a 6 KB
// buffer each, ~100k of them on Ratboy at 0.5 mm), took 1.2 s of the 1.3 s
// voxelization there, and the light caches and rates volumes are allocated
// the same way (tens to hundreds of MB, once per render). jemalloc with
// thp:always advises its extents to the kernel as transparent huge pages (one
// fault per 2 MiB; used where /sys/kernel/mm/transparent_hugepage/enabled says
// "madvise" or "always"), and keeps what is freed for later allocations for
// a while (dirty_decay_ms, 10 s) rather than returning it at once. Threads
// are spread over arenas (4 per CPU); a single arena (narenas:1) lowered the
// default scene's peak (411 → 392 MiB, the time within noise) but would
// contend on a many-core machine, so the default stays.
//
// MALLOC_CONF in the environment is read after this and overrides it
// (jemalloc(3), "TUNING").

// jemalloc reads this symbol when it initialises (jemalloc(3): malloc_conf).
extern "C" const char* malloc_conf;
const char* malloc_conf = "thp:always,metadata_thp:always";
