#pragma once
/// \file ChildSignals.hpp
/// Forking a child of the server (a solver, an upload check) without letting a signal meant for the
/// child reach the server: the child starts as a copy of the server, signal handlers included, and
/// Asio's SIGTERM handler writes into the server's signal pipe, so a SIGTERM arriving between fork and
/// exec would shut the *server* down. The parent forks with every signal blocked; the child restores
/// the default dispositions before it unblocks them (what posix_spawn's SETSIGDEF does).

#include <pthread.h>
#include <signal.h>

namespace rcfd::server {

/// Blocks every signal in the calling thread; returns the mask to restore after the fork.
inline sigset_t blockAllSignals() {
  sigset_t all, previous;
  ::sigfillset(&all);
  ::pthread_sigmask(SIG_BLOCK, &all, &previous);
  return previous;
}

/// In the child, before exec (async-signal-safe calls only): default dispositions for every signal,
/// SIGPIPE ignored when `ignoreSigpipe`, then nothing blocked.
inline void defaultSignalsInChild(bool ignoreSigpipe) {
  struct sigaction byDefault {};
  byDefault.sa_handler = SIG_DFL;
  ::sigemptyset(&byDefault.sa_mask);
  for (int sig = 1; sig < NSIG; ++sig)
    if (sig != SIGKILL && sig != SIGSTOP) ::sigaction(sig, &byDefault, nullptr);
  if (ignoreSigpipe) ::signal(SIGPIPE, SIG_IGN);
  sigset_t none;
  ::sigemptyset(&none);
  ::sigprocmask(SIG_SETMASK, &none, nullptr);
}

}  // namespace rcfd::server
