#pragma once
// The programs under test as child processes (fork/exec): an rcfd-server listening on loopback, and
// the exec step the client runner shares with it. Header-only, without GoogleTest and without the
// build's paths, so that bench/server_load.cpp starts its server with the same code as the tests.

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <charconv>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace rcfd::test {

/// Replaces this (forked) process with `args`; args[0] is a path or a name looked up in PATH (a
/// wrapper such as valgrind). Exits with 127, as a shell does, when it cannot be executed.
[[noreturn]] inline void execOrExit(std::vector<std::string> args) {
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  ::execvp(argv[0], argv.data());
  ::_exit(127);
}

/// How a ServerChild starts rcfd-server: the command line, and the options a caller sets as it needs.
struct ServerCommand {
  explicit ServerCommand(std::vector<std::string> args) : args(std::move(args)) {}

  /// rcfd-server (or a wrapper running it) and the arguments.
  std::vector<std::string> args;
  /// The child's stderr, appended to so that a restarted server adds to what its predecessor wrote;
  /// empty: the child writes to this process's stderr.
  std::filesystem::path stderrFile;
  /// > 0: the child's limit of open descriptors (RLIMIT_NOFILE), for tests of descriptor exhaustion.
  int fileLimit = 0;
  /// Variables the child must not inherit (RCFD_TOKEN, for a server that has to make its own token).
  std::vector<std::string> unsetEnvironment;
};

/// An rcfd-server child process from fork/exec until it is stopped (by the destructor with SIGTERM,
/// if not before). The constructor returns once the server has printed its first stdout line (or
/// closed stdout): "listening on http://HOST:PORT" (https:// with --tls-cert) once it listens, which
/// is how a caller that asked for port 0 learns the port. A server that did not get that far is not
/// an error here: callers check listening() and report it their way.
class ServerChild {
 public:
  explicit ServerChild(ServerCommand command) {
    int out[2];
    if (::pipe(out) != 0) throw std::runtime_error("pipe");
    pid_ = ::fork();
    if (pid_ < 0) {
      ::close(out[0]);
      ::close(out[1]);
      throw std::runtime_error("fork");
    }
    if (pid_ == 0) {
      for (const auto& name : command.unsetEnvironment) ::unsetenv(name.c_str());
      if (command.fileLimit > 0) {
        const rlimit limit{rlim_t(command.fileLimit), rlim_t(command.fileLimit)};
        ::setrlimit(RLIMIT_NOFILE, &limit);
      }
      ::dup2(out[1], STDOUT_FILENO);
      ::close(out[0]);
      ::close(out[1]);
      if (!command.stderrFile.empty()) {
        const int err = ::open(command.stderrFile.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
        ::dup2(err, STDERR_FILENO);
      }
      execOrExit(std::move(command.args));
    }
    ::close(out[1]);
    char c;
    while (::read(out[0], &c, 1) == 1 && c != '\n') firstLine_.push_back(c);
    ::close(out[0]);
    const bool https = firstLine_.rfind("listening on https://", 0) == 0;
    const auto colon = firstLine_.rfind(':');
    if ((https || firstLine_.rfind("listening on http://", 0) == 0) && colon != std::string::npos) {
      tls_ = https;
      std::from_chars(firstLine_.data() + colon + 1, firstLine_.data() + firstLine_.size(), port_);
    }
  }
  ~ServerChild() { stop(SIGTERM); }
  ServerChild(const ServerChild&) = delete;
  ServerChild& operator=(const ServerChild&) = delete;

  /// Sends `sig` and waits for the child to end; returns its wait status (0 once it has been stopped).
  int stop(int sig) {
    int status = 0;
    if (pid_ <= 0) return status;
    ::kill(pid_, sig);
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
    return status;
  }
  bool alive() const { return pid_ > 0 && ::kill(pid_, 0) == 0; }

  /// True when the first line said the server listens; port() and tls() are only meaningful then.
  bool listening() const { return port_ != 0; }
  unsigned short port() const { return port_; }
  bool tls() const { return tls_; }
  pid_t pid() const { return pid_; }
  const std::string& firstLine() const { return firstLine_; }

 private:
  pid_t pid_ = -1;
  std::string firstLine_;
  unsigned short port_ = 0;
  bool tls_ = false;
};

}  // namespace rcfd::test
