#pragma once
/// \file WorkerPool.hpp
/// Runs queued jobs as child processes `rcfd-solve run job.json --out DIR --progress-json`, at most
/// `workers` at a time, oldest first. Each child is watched by its own thread (never an io_context
/// thread): progress lines update the job row (throttled), stderr goes to DIR/solver.log, and the exit
/// status decides the job's final state (docs/contracts.md, "Exit codes"). A crash or kill of one
/// solver fails only its job. Children get SIGTERM if the server dies (PR_SET_PDEATHSIG), so they
/// checkpoint and the restarted server resumes them from the same out directory.

#include <chrono>
#include <condition_variable>
#include <map>
#include <mutex>
#include <string>
#include <sys/types.h>
#include <thread>
#include <vector>

#include "JobExecutor.hpp"
#include "JobStore.hpp"
#include "ServerConfig.hpp"

namespace rcfd::server {

/// The environment of a solver child: `environment` (the server's own), plus OMP_NUM_THREADS = the
/// `cores` shared among `workers` solvers (at least 1 each) where `environment` does not set it, so
/// that the server's own solvers never put two spinning OpenMP threads on one core (docs/deploy.md).
std::vector<std::string> solverEnvironment(int workers, const char* const* environment, unsigned cores);
/// The same for this process's environment and hardware threads.
std::vector<std::string> solverEnvironment(int workers);

class WorkerPool final : public JobExecutor {
 public:
  WorkerPool(JobStore& store, const ServerConfig& config);
  ~WorkerPool() override;
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  /// Re-queues jobs a previous server left RUNNING (CANCELLING ones become CANCELLED) and starts
  /// the scheduler.
  void start() override;
  /// Something changed (a job was queued or finished): look for work now.
  void wake() override;
  /// Sends SIGTERM to the job's solver if one is running; the job is already CANCELLING.
  void terminate(const std::string& id) override;
  /// Stops starting jobs, sends SIGTERM to every solver, waits for them (up to the grace period,
  /// then SIGKILL); jobs interrupted this way go back to QUEUED and resume on the next start.
  void shutdown() override;

  int busy() override;
  int slots() const override { return config_.workers; }

 private:
  void schedulerLoop();
  void runJob(JobRecord job, std::uint64_t run);
  void finishJob(const JobRecord& job, int waitStatus, const std::string& reasonTail, bool killedAfterCancel);

  JobStore& store_;
  const ServerConfig& config_;
  std::mutex mutex_;
  std::mutex shutdownMutex_;  // serialises shutdown() calls
  std::condition_variable wake_;
  bool stopping_ = false;
  bool pending_ = false;
  std::map<std::string, pid_t> children_;
  /// When each running job's cancel was sent (SIGTERM): past config.cancelGrace its solver is killed.
  std::map<std::string, std::chrono::steady_clock::time_point> cancelSent_;
  std::map<std::uint64_t, std::thread> threads_;  // by run number (a re-queued job runs again)
  std::vector<std::uint64_t> finished_;
  std::uint64_t runs_ = 0;
  std::thread scheduler_;
};

}  // namespace rcfd::server
