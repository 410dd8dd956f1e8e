#pragma once
/// \file SolveChild.hpp
/// The real rcfd-solve binary as a child process whose --progress-json lines are read as they come,
/// so a test can wait for a phase, send a signal and time the exit, as the server's cancel does.

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "SolveProcess.hpp"

namespace rcfd::test {

class SolveChild {
 public:
  /// Starts `rcfd-solve args...`; stdout is read here, stderr goes to `stderrPath`.
  SolveChild(const std::vector<std::string>& args, std::filesystem::path stderrPath)
      : stderrPath_(std::move(stderrPath)) {
    int out[2];
    if (::pipe2(out, O_CLOEXEC) != 0) throw std::runtime_error("pipe");
    std::vector<std::string> argv = {kSolver};
    argv.insert(argv.end(), args.begin(), args.end());
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(out[1], 1);
      const int err = ::open(stderrPath_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(err, 2);
      std::vector<char*> raw;
      for (auto& a : argv) raw.push_back(a.data());
      raw.push_back(nullptr);
      ::execv(raw[0], raw.data());
      ::_exit(127);
    }
    ::close(out[1]);
    out_ = out[0];
  }
  ~SolveChild() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
    if (out_ >= 0) ::close(out_);
  }
  SolveChild(const SolveChild&) = delete;
  SolveChild& operator=(const SolveChild&) = delete;

  /// Reads progress lines until one satisfies `wanted` and returns it; null when the process ended
  /// or `timeoutSeconds` passed first.
  nlohmann::json waitForProgress(const std::function<bool(const nlohmann::json&)>& wanted, double timeoutSeconds) {
    const auto deadline = Clock::now() + seconds(timeoutSeconds);
    std::size_t seen = 0;
    while (Clock::now() < deadline) {
      for (; seen < progress_.size(); ++seen)
        if (wanted(progress_[seen])) return progress_[seen];
      if (!readFor(std::chrono::milliseconds(50))) break;
    }
    for (; seen < progress_.size(); ++seen)
      if (wanted(progress_[seen])) return progress_[seen];
    return nullptr;
  }
  nlohmann::json waitForPhase(const std::string& phase, double timeoutSeconds) {
    return waitForProgress([&](const nlohmann::json& p) { return p.value("phase", "") == phase; }, timeoutSeconds);
  }

  /// Sends `sig` and waits for the exit, at most `timeoutSeconds` (then SIGKILL); returns the seconds
  /// from the signal to the exit. Keeps reading stdout meanwhile: a child blocked on a full pipe
  /// could not exit.
  double signalAndWait(int sig, double timeoutSeconds) {
    const auto sent = Clock::now();
    ::kill(pid_, sig);
    const auto deadline = sent + seconds(timeoutSeconds);
    for (;;) {
      int status = 0;
      const pid_t done = ::waitpid(pid_, &status, WNOHANG);
      if (done == pid_) {
        const double took = std::chrono::duration<double>(Clock::now() - sent).count();
        pid_ = -1;
        exitCode_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        while (readFor(std::chrono::milliseconds(0))) {
        }
        return took;
      }
      if (Clock::now() > deadline) {
        ::kill(pid_, SIGKILL);
        ::waitpid(pid_, nullptr, 0);
        pid_ = -1;
        return std::chrono::duration<double>(Clock::now() - sent).count();
      }
      if (!readFor(std::chrono::milliseconds(10))) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  /// Waits for the exit without a signal; the exit code, or -1 after `timeoutSeconds`.
  int wait(double timeoutSeconds) {
    const auto deadline = Clock::now() + seconds(timeoutSeconds);
    while (Clock::now() < deadline) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        exitCode_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        while (readFor(std::chrono::milliseconds(0))) {
        }
        return exitCode_;
      }
      if (!readFor(std::chrono::milliseconds(50))) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return -1;
  }

  int exitCode() const { return exitCode_; }  ///< -1 while running or when killed after a timeout
  const std::vector<nlohmann::json>& progress() const { return progress_; }
  std::string stderrText() const {
    std::ifstream in(stderrPath_);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }

 private:
  using Clock = std::chrono::steady_clock;
  static Clock::duration seconds(double s) {
    return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
  }
  /// Reads what stdout has within `wait`; false once it is closed (the child exited).
  bool readFor(std::chrono::milliseconds wait) {
    if (out_ < 0) return false;
    pollfd ready{out_, POLLIN, 0};
    if (::poll(&ready, 1, int(wait.count())) <= 0) return true;
    char chunk[4096];
    const ssize_t n = ::read(out_, chunk, sizeof chunk);
    if (n <= 0) {
      ::close(out_);
      out_ = -1;
      return false;
    }
    buffer_.append(chunk, std::size_t(n));
    for (std::size_t eol; (eol = buffer_.find('\n')) != std::string::npos;) {
      auto line = nlohmann::json::parse(buffer_.substr(0, eol), nullptr, false);
      buffer_.erase(0, eol + 1);
      if (line.is_object()) progress_.push_back(std::move(line));
    }
    return true;
  }

  std::filesystem::path stderrPath_;
  pid_t pid_ = -1;
  int out_ = -1;
  int exitCode_ = -1;
  std::string buffer_;
  std::vector<nlohmann::json> progress_;
};

}  // namespace rcfd::test
