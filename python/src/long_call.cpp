#include "long_call.h"

#include <hairvox/core/error.h>
#include <hairvox/core/interrupt.h>
#include <hairvox/core/progress.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

namespace hairvox::python {

namespace {

/// How often the waiting caller checks signals and progress.
constexpr std::chrono::milliseconds kPollInterval{50};

/// One long call at a time (see long_call.h).
std::mutex gLongCallMutex;

/// What the callback was last told, to call it only when something changed
/// and to close a stage (done = total) when the next one starts.
struct Reported {
    std::uint64_t serial = 0;
    std::string title;
    std::uint64_t done = 0, total = 0;
    bool any = false;
};

void report(const py::object& callback, const std::string& title, std::uint64_t done,
            std::uint64_t total) {
    callback(title, done, total);
}

/// Calls the callback for the current stage if it moved on; a stage that
/// ended since (another started, or the call finished: `now` empty) is
/// reported complete first.
void reportProgress(const py::object& callback, const std::optional<ProgressSnapshot>& now,
                    Reported& last) {
    const bool sameStage = now && last.any && now->serial == last.serial;
    if (last.any && !sameStage && last.done < last.total) {
        report(callback, last.title, last.total, last.total);
        last.done = last.total;
    }
    if (!now || (sameStage && now->done == last.done))
        return;
    last = {now->serial, now->title, now->done, now->total, true};
    report(callback, now->title, now->done, now->total);
}

} // namespace

Progress Progress::from(py::handle value) {
    Progress p;
    if (value.is_none())
        return p;
    if (py::isinstance<py::bool_>(value)) {
        p.bars = value.cast<bool>();
        return p;
    }
    if (PyCallable_Check(value.ptr()) == 1) {
        p.callback = py::reinterpret_borrow<py::object>(value);
        return p;
    }
    throw InputError(strCat("progress: expected None, True (bars on stderr) or a callable "
                            "(stage, done, total), got ",
                            typeName(value)));
}

namespace detail {

void runLongCall(const Progress& progress, const std::function<void()>& work) {
    std::unique_lock callLock(gLongCallMutex, std::defer_lock);
    {
        py::gil_scoped_release released;
        callLock.lock();
    }
    clearInterrupt();

    std::mutex mutex;
    std::condition_variable finished;
    bool done = false;
    std::exception_ptr error;
    std::thread worker([&] {
        try {
            work();
        } catch (...) {
            error = std::current_exception();
        }
        {
            std::lock_guard lock(mutex);
            done = true;
        }
        finished.notify_all();
    });

    std::optional<py::error_already_set> raised; // KeyboardInterrupt, or the callback's
    Reported reported;
    for (;;) {
        {
            py::gil_scoped_release released;
            std::unique_lock lock(mutex);
            if (finished.wait_for(lock, kPollInterval, [&] { return done; }))
                break;
        }
        if (raised)
            continue; // stopping: wait for the worker to unwind
        try {
            if (PyErr_CheckSignals() != 0)
                throw py::error_already_set();
            if (progress.callback)
                reportProgress(progress.callback, currentProgress(), reported);
        } catch (py::error_already_set& e) {
            raised.emplace(std::move(e));
            requestInterrupt();
        }
    }
    {
        py::gil_scoped_release released;
        worker.join();
    }
    clearInterrupt();
    callLock.unlock();

    if (raised)
        throw std::move(*raised);
    if (error)
        std::rethrow_exception(error);
    if (progress.callback)
        reportProgress(progress.callback, std::nullopt, reported);
}

} // namespace detail

void bindLongCalls(py::module_& m) {
    // InputError → ValueError (the CLI's message), Interrupted →
    // KeyboardInterrupt, any other library exception → RuntimeError;
    // pybind11's own and Python's exceptions pass through.
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            std::rethrow_exception(p);
        } catch (const py::error_already_set&) {
            throw;
        } catch (const py::builtin_exception&) {
            throw;
        } catch (const InputError& e) {
            PyErr_SetString(PyExc_ValueError, e.what());
        } catch (const Interrupted& e) {
            PyErr_SetString(PyExc_KeyboardInterrupt, e.what());
        } catch (const std::bad_alloc&) {
            PyErr_SetString(PyExc_MemoryError, "hairvox: out of memory");
        } catch (const std::exception& e) {
            PyErr_SetString(PyExc_RuntimeError, e.what());
        }
    });
    m.def(
        "interrupt", [] { requestInterrupt(); },
        R"doc(Stops the long call now running (from another thread: a GUI's stop button).

The call raises KeyboardInterrupt once it has unwound, as Ctrl-C makes it do;
nothing is left half-written. Without a call running, nothing happens (the
next call starts afresh).)doc");
}

} // namespace hairvox::python
