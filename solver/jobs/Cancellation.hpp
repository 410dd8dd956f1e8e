#pragma once
/// \file Cancellation.hpp
/// SIGINT/SIGTERM turn into a flag that long loops poll between steps; the job then writes its
/// checkpoint where its phase has one and ends with rcfd::Cancelled (exit 130). Installing is explicit
/// (the CLI does it), so tests and library users keep their own signal handling.
///
/// A cancelled solver must be gone within seconds (the server's cancel), but a few steps
/// cannot look at the flag: one coupling step of 10^5 DEM steps, one tracer step of 10^8 tracers, one
/// HDF5 write. The cancellation watchdog is the bound for those: once the flag has been set for
/// `deadlineSeconds` it ends the process with exit 130, without unwinding. Writes that must not be cut
/// (a file kept after the process, written in place; a checkpoint) hold it off with a
/// ForcedExitDeferral while they run, so a forced exit leaves every file as a kill between two of
/// them would, which the jobs resume from.

namespace rcfd {

/// Installs handlers for SIGINT and SIGTERM that set the cancellation flag.
void installCancellationHandlers();
bool cancellationRequested();
/// Sets or clears the flag (tests; a second job in the same process).
void requestCancellation(bool value = true);
/// Seconds since the flag was set (0 while it is clear).
double secondsSinceCancellation();

/// Starts the watchdog thread (once per process; later calls change the deadline): `deadlineSeconds`
/// after the flag is set it writes a line to stderr and calls _exit(130), waiting for any
/// ForcedExitDeferral to end first.
void startCancellationWatchdog(double deadlineSeconds);

/// While alive, the watchdog does not end the process. Nestable and usable from several threads. A
/// deferral begun after the watchdog decided to end the process blocks until it does: that write
/// never starts.
class ForcedExitDeferral {
 public:
  ForcedExitDeferral();
  ~ForcedExitDeferral();
  ForcedExitDeferral(const ForcedExitDeferral&) = delete;
  ForcedExitDeferral& operator=(const ForcedExitDeferral&) = delete;
};

}  // namespace rcfd
