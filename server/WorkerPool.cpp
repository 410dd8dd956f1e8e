#include "WorkerPool.hpp"

#include <poll.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "ChildSignals.hpp"
#include "SolverRun.hpp"
#include "core/Errors.hpp"

namespace rcfd::server {

namespace {

constexpr auto kProgressWriteInterval = std::chrono::milliseconds(250);  // throttle row updates

}  // namespace

std::vector<std::string> solverEnvironment(int workers, const char* const* environment, unsigned cores) {
  std::vector<std::string> env;
  bool threads = false;
  for (const char* const* e = environment; e && *e; ++e) {
    const std::string entry = *e;
    threads = threads || entry.starts_with("OMP_NUM_THREADS=");
    env.push_back(entry);
  }
  if (!threads) env.push_back("OMP_NUM_THREADS=" + std::to_string(std::max(1u, cores / unsigned(std::max(1, workers)))));
  return env;
}

std::vector<std::string> solverEnvironment(int workers) {
  return solverEnvironment(workers, environ, std::thread::hardware_concurrency());
}

WorkerPool::WorkerPool(JobStore& store, const ServerConfig& config)
    : store_(store), config_(config) {}

WorkerPool::~WorkerPool() { shutdown(); }

void WorkerPool::start() {
  for (const auto& job : store_.unfinished()) {
    if (job.state == state::running)
      store_.transition(job.id, state::running, state::queued,
                        "server restarted; the job resumes from its checkpoint");
    else
      store_.transition(job.id, state::cancelling, state::cancelled,
                        "server restarted while the job was cancelling");
  }
  scheduler_ = std::thread(&WorkerPool::schedulerLoop, this);
}

void WorkerPool::wake() {
  {
    std::lock_guard lock(mutex_);
    pending_ = true;
  }
  wake_.notify_all();
}

int WorkerPool::busy() {
  std::lock_guard lock(mutex_);
  return static_cast<int>(threads_.size() - finished_.size());
}

void WorkerPool::terminate(const std::string& id) {
  std::lock_guard lock(mutex_);
  auto it = children_.find(id);
  if (it == children_.end()) return;
  ::kill(it->second, SIGTERM);
  cancelSent_.emplace(id, std::chrono::steady_clock::now());
}

void WorkerPool::schedulerLoop() {
  for (;;) {
    std::vector<std::thread> toJoin;
    int freeSlots = 0;
    {
      std::unique_lock lock(mutex_);
      // Wake on demand, and every second anyway so jobs waiting on a database job are picked up.
      wake_.wait_for(lock, std::chrono::seconds(1), [&] { return stopping_ || pending_; });
      pending_ = false;
      if (stopping_) return;
      for (const auto& id : finished_) {
        toJoin.push_back(std::move(threads_.at(id)));
        threads_.erase(id);
      }
      finished_.clear();
      freeSlots = config_.workers - static_cast<int>(threads_.size());
    }
    for (auto& t : toJoin) t.join();
    if (freeSlots <= 0) continue;
    for (auto& job : store_.queued(256)) {
      if (freeSlots <= 0) break;
      if (!databaseReady(store_, config_, job)) continue;
      if (!store_.markStarted(job.id)) continue;  // cancelled meanwhile
      std::lock_guard lock(mutex_);
      if (stopping_) {
        store_.transition(job.id, state::running, state::queued, "server shutting down");
        return;
      }
      const std::uint64_t run = ++runs_;
      threads_.emplace(run, std::thread(&WorkerPool::runJob, this, job, run));
      --freeSlots;
    }
  }
}

void WorkerPool::runJob(JobRecord job, std::uint64_t run) {
  namespace fs = std::filesystem;
  const fs::path dir = config_.jobDir(job.id);
  const fs::path log = dir / "solver.log";
  std::streamoff logStart = 0;
  int waitStatus = -1;
  bool killedAfterCancel = false;
  std::string setupError;
  try {
    writeJobFile(store_, config_, job);
    if (fs::exists(log)) logStart = static_cast<std::streamoff>(fs::file_size(log));
  } catch (const std::exception& e) {
    setupError = std::string("could not prepare the job directory: ") + e.what();
  }

  int logFd = -1, pipeFds[2] = {-1, -1};
  pid_t pid = -1;
  if (setupError.empty()) {
    logFd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0600);
    if (logFd < 0 || ::pipe2(pipeFds, O_CLOEXEC) != 0)
      setupError = std::string("cannot open the solver log or pipe: ") + std::strerror(errno);
  }
  if (setupError.empty()) {
    const std::string header = "=== attempt " + std::to_string(job.attempt + 1) + " at " +
                               nowRfc3339() + " of " + job.owner + "'s job ===\n";
    (void)!::write(logFd, header.data(), header.size());
    logStart += static_cast<std::streamoff>(header.size());
    const std::string solver = config_.solverPath.string();
    const std::string jobFile = (dir / "job.json").string();
    const std::string outDir = dir.string();
    std::vector<const char*> argv = {solver.c_str(), "run", jobFile.c_str(), "--out",
                                     outDir.c_str(), "--progress-json", nullptr};
    // The environment is built before the fork: nothing after it may allocate.
    std::vector<std::string> environment = solverEnvironment(config_.workers);
    std::vector<const char*> envp;
    for (const auto& e : environment) envp.push_back(e.c_str());
    envp.push_back(nullptr);
    const pid_t parent = ::getpid();
    // Solvers are batch work: nicer than the server, whose I/O threads answer polls in microseconds
    // and would otherwise queue behind a solver's threads for a scheduler slice.
    const int solverNice = std::min(19, ::getpriority(PRIO_PROCESS, 0) + config_.workerNice);
    // A cancel (SIGTERM) must not reach the server's handlers in the child (ChildSignals.hpp).
    const sigset_t previous = blockAllSignals();
    pid = ::fork();
    if (pid == 0) {
      // Child: only async-signal-safe calls until exec. SIGPIPE stays ignored, as in the server: a
      // solver whose server died must get EPIPE on its progress pipe and go on to checkpoint on the
      // PDEATHSIG SIGTERM, not die of SIGPIPE first. A pending SIGTERM then ends the child: cancelled.
      defaultSignalsInChild(true);
      ::setpgid(0, 0);                      // a terminal's Ctrl-C reaches the server only
      ::setpriority(PRIO_PROCESS, 0, solverNice);  // the solver's threads inherit it
      ::prctl(PR_SET_PDEATHSIG, SIGTERM);   // server gone -> checkpoint and exit 130
      if (::getppid() != parent) ::_exit(130);
      const int devnull = ::open("/dev/null", O_RDONLY);
      ::dup2(devnull, 0);
      ::dup2(pipeFds[1], 1);
      ::dup2(logFd, 2);
      // The solver must not hold the server's sockets (listener, client connections): a connection
      // it kept open would outlive the server's close or be reset when the solver exits.
      ::close_range(3, ~0U, 0);
      ::execve(argv[0], const_cast<char* const*>(argv.data()), const_cast<char* const*>(envp.data()));
      const char msg[] = "rcfd-server: cannot execute the solver\n";
      (void)!::write(2, msg, sizeof msg - 1);
      ::_exit(127);
    }
    ::pthread_sigmask(SIG_SETMASK, &previous, nullptr);
    ::close(pipeFds[1]);
    if (pid < 0) {
      setupError = std::string("fork failed: ") + std::strerror(errno);
      ::close(pipeFds[0]);
    }
  }
  if (logFd >= 0) ::close(logFd);

  if (setupError.empty()) {
    {
      std::lock_guard lock(mutex_);
      children_[job.id] = pid;
    }
    // Cancel or shutdown may have come between markStarted and the fork.
    if (auto now = store_.job(job.id); now && now->state == state::cancelling) terminate(job.id);
    {
      std::lock_guard lock(mutex_);
      if (stopping_) ::kill(pid, SIGTERM);
    }
    std::string buffer;
    char chunk[4096];
    auto lastWrite = std::chrono::steady_clock::now() - kProgressWriteInterval;
    nlohmann::json latest;
    for (;;) {
      // Wake at least once a second: a solver that ignores its cancel is killed after the grace period.
      pollfd ready{pipeFds[0], POLLIN, 0};
      if (::poll(&ready, 1, 1000) == 0) {
        std::lock_guard lock(mutex_);
        const auto sent = cancelSent_.find(job.id);
        if (!killedAfterCancel && sent != cancelSent_.end() &&
            std::chrono::steady_clock::now() - sent->second > config_.cancelGrace) {
          ::kill(pid, SIGKILL);
          killedAfterCancel = true;
        }
        continue;
      }
      const ssize_t n = ::read(pipeFds[0], chunk, sizeof chunk);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      buffer.append(chunk, static_cast<std::size_t>(n));
      std::size_t eol;
      while ((eol = buffer.find('\n')) != std::string::npos) {
        const std::string line = buffer.substr(0, eol);
        buffer.erase(0, eol + 1);
        auto parsed = nlohmann::json::parse(line, nullptr, false);
        if (parsed.is_object() && parsed.contains("fraction")) latest = std::move(parsed);
      }
      const auto now = std::chrono::steady_clock::now();
      if (!latest.is_null() && now - lastWrite >= kProgressWriteInterval) {
        storeProgress(store_, job.id, latest);
        lastWrite = now;
        latest = nullptr;
      }
    }
    ::close(pipeFds[0]);
    if (!latest.is_null())
      storeProgress(store_, job.id, latest);
    while (::waitpid(pid, &waitStatus, 0) < 0 && errno == EINTR) {
    }
    std::lock_guard lock(mutex_);
    children_.erase(job.id);
    cancelSent_.erase(job.id);
  }

  if (!setupError.empty()) {
    if (!store_.transition(job.id, state::running, state::failed, {}, setupError))
      store_.transition(job.id, state::cancelling, state::cancelled, "cancelled before start");
  } else {
    finishJob(job, waitStatus, logTail(log, logStart), killedAfterCancel);
  }
  {
    std::lock_guard lock(mutex_);
    finished_.push_back(run);
    pending_ = true;
  }
  wake_.notify_all();
}

void WorkerPool::finishJob(const JobRecord& job, int waitStatus, const std::string& reasonTail, bool killedAfterCancel) {
  bool stopping;
  {
    std::lock_guard lock(mutex_);
    stopping = stopping_;
  }
  const auto current = store_.job(job.id);
  const bool cancelling = current && current->state == state::cancelling;
  const std::string from = cancelling ? state::cancelling : state::running;
  const auto withTail = [&](std::string reason) {
    return reasonTail.empty() ? reason : reason + ": " + reasonTail;
  };

  if (WIFEXITED(waitStatus)) {
    const int code = WEXITSTATUS(waitStatus);
    if (code == exit_code::success) {
      storeSucceeded(store_, config_, job.id, from);
      return;
    }
    if (code == exit_code::cancelled) {
      if (cancelling) {
        // A cancel in the DEM fill stops before there is any state worth a checkpoint.
        std::error_code ec;
        const bool checkpoint = std::filesystem::exists(config_.jobDir(job.id) / "checkpoint.h5", ec);
        store_.transition(job.id, from, state::cancelled,
                          checkpoint ? "the solver checkpointed and stopped"
                                     : "the solver stopped before its first checkpoint; a retry starts from the beginning");
      } else if (stopping)
        store_.transition(job.id, from, state::queued,
                          "server shut down; the job resumes from its checkpoint");
      else
        store_.transition(job.id, from, state::failed, {},
                          withTail("the solver was stopped from outside the server (exit 130)"));
      return;
    }
    std::string what = code == exit_code::invalid_input ? "the solver rejected the job (exit 2)"
                       : code == exit_code::run_failed  ? "the run failed (exit 3)"
                       : code == 127 ? "the solver could not be executed (exit 127)"
                                     : "the solver exited with code " + std::to_string(code);
    store_.transition(job.id, from, cancelling ? state::cancelled : state::failed, {},
                      withTail(what));
    return;
  }
  if (WIFSIGNALED(waitStatus)) {
    const int sig = WTERMSIG(waitStatus);
    if (stopping && !cancelling && sig == SIGTERM) {
      store_.transition(job.id, from, state::queued, "server shut down before the solver checkpointed");
      return;
    }
    if (killedAfterCancel) {
      store_.transition(job.id, from, state::cancelled,
                        "the solver did not stop within " + std::to_string(config_.cancelGrace.count()) +
                            " s of the cancel and was killed (SIGKILL); its checkpoint, if any, is kept");
      return;
    }
    // Killed from outside (the kernel's out-of-memory killer sends SIGKILL): the checkpoint is intact,
    // so the job resumes from it, a limited number of times since a job that needs too much memory
    // will be killed again.
    const int attempts = current ? current->attempt : job.attempt;  // `job` was read before it started
    if (sig == SIGKILL && !cancelling && !stopping && attempts <= config_.autoRetries &&
        store_.transition(job.id, from, state::queued,
                          "the solver was killed by SIGKILL (out of memory?); queued again to resume from its "
                          "checkpoint (automatic retry " + std::to_string(attempts) + " of " +
                              std::to_string(config_.autoRetries) + ")")) {
      wake();
      return;
    }
    store_.transition(job.id, from, cancelling ? state::cancelled : state::failed, {},
                      withTail("the solver was killed by " + signalName(sig)));
    return;
  }
  store_.transition(job.id, from, state::failed, {}, "the solver ended in an unknown way");
}

void WorkerPool::shutdown() {
  // One shutdown at a time (the signal handler's and main's, then the destructor's): a second caller
  // waits for the first and then finds nothing left to do.
  std::lock_guard once(shutdownMutex_);
  std::map<std::uint64_t, std::thread> threads;
  {
    std::lock_guard lock(mutex_);
    if (stopping_ && !scheduler_.joinable()) return;
    stopping_ = true;
    for (const auto& [id, pid] : children_) ::kill(pid, SIGTERM);
  }
  wake_.notify_all();
  if (scheduler_.joinable()) scheduler_.join();
  // Wait for the solvers to checkpoint; past the grace period, SIGKILL what is left.
  const auto deadline = std::chrono::steady_clock::now() + config_.shutdownGrace;
  for (;;) {
    {
      std::lock_guard lock(mutex_);
      if (children_.empty()) break;
      if (std::chrono::steady_clock::now() > deadline)
        for (const auto& [id, pid] : children_) ::kill(pid, SIGKILL);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  {
    std::lock_guard lock(mutex_);
    threads.swap(threads_);
    finished_.clear();
  }
  for (auto& [id, t] : threads)
    if (t.joinable()) t.join();
}

}  // namespace rcfd::server
