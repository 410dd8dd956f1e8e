#pragma once
/// \file SlurmExecutor.hpp
/// `rcfd-server --executor slurm`: each job runs as a Slurm batch job (docs/cluster.md). The server
/// writes the job's directory on the data directory that the compute nodes share, submits
/// DIR/slurm-job.sh with sbatch and stores the Slurm job id with the job. The batch script runs
/// `rcfd-solve run job.json --out DIR --progress-json` in DIR, progress lines to DIR/progress.jsonl,
/// and leaves the solver's exit code in DIR/slurm-<slurm id>.exit.
///
/// One thread does all the talking to Slurm: it submits queued jobs, and every poll interval it asks
/// squeue once for the states of all the server's Slurm jobs and reads each running job's last progress
/// line. HTTP requests only read the store, so a status poll never waits for Slurm. A job Slurm ends
/// TIMEOUT, NODE_FAIL or PREEMPTED (or whose solver checkpointed on the SIGTERM Slurm sends ahead of the
/// time limit) is submitted again, up to SlurmSettings::requeues times, and resumes from its checkpoint.
/// A cancel sends SIGTERM to the batch shell (scancel --batch --signal=TERM), which passes it on to the
/// solver so that it checkpoints; after the cancel grace period the Slurm job is cancelled outright.
/// Jobs keep running in Slurm when the server stops; the next server follows them by their stored ids.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <thread>

#include "JobExecutor.hpp"
#include "JobStore.hpp"
#include "ServerConfig.hpp"

namespace rcfd::server {

class SlurmExecutor final : public JobExecutor {
 public:
  SlurmExecutor(JobStore& store, const ServerConfig& config);
  ~SlurmExecutor() override;
  SlurmExecutor(const SlurmExecutor&) = delete;
  SlurmExecutor& operator=(const SlurmExecutor&) = delete;

  /// Follows the Slurm jobs of the jobs a previous server left RUNNING or CANCELLING: by their stored
  /// Slurm ids, or, where the server stopped before it stored one, by their Slurm job names (a job that
  /// squeue does not list under its name never reached Slurm and is queued again). Then starts the
  /// thread that talks to Slurm.
  void start() override;
  void wake() override;
  /// Queues the cancel for the Slurm thread (scancel is never run on an HTTP thread).
  void terminate(const std::string& id) override;
  /// Stops the Slurm thread; the jobs go on running in Slurm and stay RUNNING in the store.
  void shutdown() override;

  int busy() override { return busy_.load(); }
  int slots() const override { return config_.slurm.maxJobs; }

 private:
  /// A job in Slurm that this server follows.
  struct Followed {
    std::string slurmJobId;              ///< empty until squeue lists slurmJobName (a restart's lookup)
    std::string slurmJobName;            ///< rcfd-<id>-<attempt>
    std::string slurmState;              ///< as squeue last reported it; empty before the first poll
    std::uintmax_t progressBytes = 0;    ///< size of progress.jsonl when last read
    std::uintmax_t logStart = 0;         ///< size of solver.log before this attempt
    int pollsUnlisted = 0;               ///< consecutive polls in which squeue did not list the job
    bool cancelSent = false;             ///< SIGTERM asked for (scancel --batch --signal=TERM)
    bool killSent = false;               ///< plain scancel sent after the cancel grace period
    std::chrono::steady_clock::time_point cancelSentAt;
  };

  void loop();
  void submitQueued();
  void submit(const JobRecord& job);
  void sendCancels();
  void poll();
  void readProgress(const std::string& id, Followed& followed);
  /// Ends the job whose Slurm job ended in `slurmState` (empty: Slurm no longer lists it).
  void finish(const std::string& id, Followed& followed, const std::string& slurmState);
  void follow(const std::string& id, Followed followed);
  /// A job a previous server left RUNNING or CANCELLING that Slurm never got: QUEUED or CANCELLED.
  void notInSlurm(const std::string& id);

  JobStore& store_;
  const ServerConfig& config_;
  std::string user_;  ///< whose Slurm jobs squeue lists: the server's own
  std::mutex mutex_;
  std::mutex shutdownMutex_;  // serialises shutdown() calls (the signal handler's, main's, the destructor's)
  std::condition_variable wake_;
  bool stopping_ = false;
  bool pending_ = false;
  std::set<std::string> cancelRequests_;      // under mutex_
  std::map<std::string, Followed> followed_;  // the Slurm thread's alone (start() fills it before the thread runs)
  std::atomic<int> busy_{0};
  bool squeueFailing_ = false;                // so a Slurm outage is reported once, not every poll
  std::thread thread_;
};

}  // namespace rcfd::server
