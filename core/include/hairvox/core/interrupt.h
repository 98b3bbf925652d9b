// hairvox core: cooperative interruption (Ctrl-C).
//
// The CLI installs a SIGINT/SIGTERM handler that only sets a flag; long
// operations poll it between chunks of work through throwIfInterrupted(), so
// an interrupted render unwinds normally and removes its temporary outputs.
#pragma once

namespace hairvox {

/// Async-signal-safe.
void requestInterrupt() noexcept;
bool interruptRequested() noexcept;
void clearInterrupt() noexcept;

/// Throws Interrupted if the user asked to stop.
void throwIfInterrupted();

/// SIGINT and SIGTERM request an interrupt; a second SIGINT terminates at once.
void installInterruptHandler();

} // namespace hairvox
