#pragma once
/// \file JobExecutor.hpp
/// Where the server's jobs run: `rcfd-server --executor local` runs each as a child process on this
/// machine (WorkerPool), `--executor slurm` submits each to a Slurm cluster (SlurmExecutor). Either way
/// the job runs `rcfd-solve run job.json --out DIR --progress-json` in its job directory, and the
/// executor alone moves a started job on (RUNNING -> SUCCEEDED/FAILED/CANCELLED/QUEUED) in the store.
/// The HTTP side calls only these members, and none of them waits for a solver or a cluster.

#include <string>

namespace rcfd::server {

class JobExecutor {
 public:
  virtual ~JobExecutor() = default;

  /// Takes over the jobs a previous server left RUNNING or CANCELLING, then starts scheduling.
  virtual void start() = 0;
  /// Something changed (a job was queued or finished): look for work now.
  virtual void wake() = 0;
  /// Asks the job's solver to checkpoint and stop; the job is already CANCELLING.
  virtual void terminate(const std::string& id) = 0;
  /// Stops scheduling; what becomes of running jobs is the executor's (see each).
  virtual void shutdown() = 0;

  /// Jobs started and not yet finished, and how many may be at once.
  virtual int busy() = 0;
  virtual int slots() const = 0;
};

}  // namespace rcfd::server
