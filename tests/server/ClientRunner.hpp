#pragma once
// Runs the `rcfd` client (build/rcfd) as a child process with its stdout and stderr captured: the
// client as users run it, against a ServerProcess.

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "ChildProcess.hpp"
#include "ServerFixture.hpp"

namespace rcfd::test {

struct Run {
  int code = -1;
  std::string out, err;
};

/// build/rcfd running in the background with its stdout and stderr captured.
struct RunningClient {
  pid_t pid = -1;
  std::unique_ptr<TempDir> capture = std::make_unique<TempDir>();
  std::filesystem::path outPath() const { return capture->path() / "out"; }
  std::filesystem::path errPath() const { return capture->path() / "err"; }
  /// Waits for it to exit.
  Run finish() {
    int status = 0;
    ::waitpid(pid, &status, 0);
    Run r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    std::ifstream o(outPath()), e(errPath());
    r.out.assign(std::istreambuf_iterator<char>(o), {});
    r.err.assign(std::istreambuf_iterator<char>(e), {});
    return r;
  }
};

/// Starts build/rcfd with arguments and extra environment. A client still running after `hangLimit`
/// is killed (SIGALRM), so that one that hangs fails its test instead of hanging the suite; 0: no limit.
inline RunningClient startClient(std::vector<std::string> args, const std::vector<std::string>& env = {},
                                 std::chrono::seconds hangLimit = std::chrono::seconds(60)) {
  const auto bin = (binaryDir() / "rcfd").string();
  args.insert(args.begin(), bin);
  RunningClient running;
  const auto outPath = running.outPath(), errPath = running.errPath();
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::alarm(static_cast<unsigned>(hangLimit.count()));
    ::unsetenv("RCFD_SERVER");
    ::unsetenv("RCFD_TOKEN");
    ::unsetenv("RCFD_CACERT");
    for (const auto& e : env) ::putenv(const_cast<char*>(e.c_str()));
    const int out = ::open(outPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = ::open(errPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(out, 1);
    ::dup2(err, 2);
    execOrExit(std::move(args));
  }
  running.pid = pid;
  return running;
}

/// Runs build/rcfd with arguments and extra environment; captures stdout and stderr.
inline Run runClient(std::vector<std::string> args, const std::vector<std::string>& env = {},
                     std::chrono::seconds hangLimit = std::chrono::seconds(60)) {
  return startClient(std::move(args), env, hangLimit).finish();
}

inline std::string firstLine(const std::string& s) { return s.substr(0, s.find('\n')); }

}  // namespace rcfd::test
