#pragma once
/// \file Cancellation.hpp
/// SIGINT/SIGTERM turn into a flag that long loops poll between steps; the job then writes its
/// checkpoint and ends with rcfd::Cancelled (exit 130). Installing is explicit (the CLI does it), so
/// tests and library users keep their own signal handling.

namespace rcfd {

/// Installs handlers for SIGINT and SIGTERM that set the cancellation flag.
void installCancellationHandlers();
bool cancellationRequested();
/// Sets or clears the flag (tests; a second job in the same process).
void requestCancellation(bool value = true);

}  // namespace rcfd
