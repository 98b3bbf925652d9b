// hairvox Python module: a long call (a render, a splat, the tables) runs
// on a worker thread while the calling thread, the GIL released, waits for
// it and every 50 ms takes the GIL to
//  - check Python's signals (PyErr_CheckSignals): Ctrl-C, or
//    _thread.interrupt_main() from another thread, raises KeyboardInterrupt
//    through Python's own handler — the module installs none. The worker is
//    then stopped by core/interrupt.h's flag (requestInterrupt()), which the
//    libraries poll between chunks, exactly as the CLI's signal handler
//    stops them, and the call raises the KeyboardInterrupt once it has
//    unwound (outputs are atomic: nothing is left half-written);
//  - report progress: the stage running (core/progress.h currentProgress())
//    to the callback, on the calling thread, with the GIL.
// The interrupt flag and TBB's thread limit are process-wide, so long calls
// run one at a time: a second caller's call waits (GIL released) for the first.
#pragma once

#include "bindings.h"

#include <exception>
#include <functional>
#include <optional>
#include <type_traits>

namespace hairvox::python {

/// How a long call reports progress: the `progress` keyword — None (not at
/// all), True (the CLI's bars on stderr) or a callable(stage: str, done: int,
/// total: int).
struct Progress {
    bool bars = false;
    py::object callback; ///< null or a callable

    static Progress from(py::handle value);
};

namespace detail {
/// Runs `work` as described above; rethrows its exception (the module's
/// translator maps InputError to ValueError, Interrupted to
/// KeyboardInterrupt, the rest to RuntimeError) or a Python exception raised
/// meanwhile (KeyboardInterrupt, the callback's).
void runLongCall(const Progress& progress, const std::function<void()>& work);
} // namespace detail

/// The value `work` returns, computed by runLongCall(). `work` must not
/// touch Python objects (it runs without the GIL).
template <typename F>
auto longCall(const Progress& progress, F&& work) {
    using R = std::invoke_result_t<F&>;
    if constexpr (std::is_void_v<R>) {
        detail::runLongCall(progress, work);
    } else {
        std::optional<R> result;
        detail::runLongCall(progress, [&] { result.emplace(work()); });
        return std::move(*result);
    }
}

} // namespace hairvox::python
