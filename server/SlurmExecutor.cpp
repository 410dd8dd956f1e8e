#include "SlurmExecutor.hpp"

#include <fcntl.h>
#include <poll.h>
#include <pwd.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>
#include <vector>

#include "ChildSignals.hpp"
#include "SolverRun.hpp"
#include "core/Errors.hpp"

namespace rcfd::server {

namespace {

constexpr auto kCommandTimeout = std::chrono::seconds(60);  // a hung slurmctld must not stop the thread for good
/// Polls in a row that must miss a job before it counts as forgotten by Slurm: one miss may be a job
/// submitted between squeue's read and ours.
constexpr int kPollsBeforeForgotten = 2;

struct CommandResult {
  int exitCode = -1;  ///< 128 + signal if it was killed; -1 if it could not be started
  std::string out, err;
};

/// `name` as execv needs it: itself if it holds a slash, else the first executable of that name in PATH
/// (found here, before the fork: the child may only make async-signal-safe calls).
std::string resolveProgram(const std::string& name) {
  if (name.find('/') != std::string::npos) return name;
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "/usr/local/bin:/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    const std::string candidate = (dir.empty() ? "." : dir) + "/" + name;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return name;
}

/// Runs a Slurm command and collects its output; killed after kCommandTimeout.
CommandResult runCommand(const std::vector<std::string>& args) {
  CommandResult result;
  const std::string program = resolveProgram(args.at(0));
  std::vector<const char*> argv;
  argv.push_back(program.c_str());
  for (std::size_t i = 1; i < args.size(); ++i) argv.push_back(args[i].c_str());
  argv.push_back(nullptr);
  int outPipe[2], errPipe[2];
  if (::pipe2(outPipe, O_CLOEXEC) != 0) {
    result.err = std::string("pipe: ") + std::strerror(errno);
    return result;
  }
  if (::pipe2(errPipe, O_CLOEXEC) != 0) {
    ::close(outPipe[0]);
    ::close(outPipe[1]);
    result.err = std::string("pipe: ") + std::strerror(errno);
    return result;
  }
  const sigset_t previous = blockAllSignals();
  const pid_t pid = ::fork();
  if (pid == 0) {
    defaultSignalsInChild(false);
    const int devnull = ::open("/dev/null", O_RDONLY);
    ::dup2(devnull, 0);
    ::dup2(outPipe[1], 1);
    ::dup2(errPipe[1], 2);
    ::close_range(3, ~0U, 0);  // not the server's sockets
    ::execv(argv[0], const_cast<char* const*>(argv.data()));
    ::_exit(127);
  }
  ::pthread_sigmask(SIG_SETMASK, &previous, nullptr);
  ::close(outPipe[1]);
  ::close(errPipe[1]);
  if (pid < 0) {
    ::close(outPipe[0]);
    ::close(errPipe[0]);
    result.err = std::string("fork: ") + std::strerror(errno);
    return result;
  }
  const auto deadline = std::chrono::steady_clock::now() + kCommandTimeout;
  pollfd fds[2] = {{outPipe[0], POLLIN, 0}, {errPipe[0], POLLIN, 0}};
  std::string* sinks[2] = {&result.out, &result.err};
  bool killed = false;
  while (fds[0].fd >= 0 || fds[1].fd >= 0) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      ::kill(pid, SIGKILL);
      killed = true;
      break;
    }
    if (::poll(fds, 2, static_cast<int>(left.count())) < 0 && errno != EINTR) break;
    for (int i = 0; i < 2; ++i) {
      if (fds[i].fd < 0 || fds[i].revents == 0) continue;
      char chunk[4096];
      const ssize_t n = ::read(fds[i].fd, chunk, sizeof chunk);
      if (n > 0) {
        sinks[i]->append(chunk, static_cast<std::size_t>(n));
      } else if (n == 0 || errno != EINTR) {
        ::close(fds[i].fd);
        fds[i].fd = -1;
      }
    }
  }
  for (auto& f : fds)
    if (f.fd >= 0) ::close(f.fd);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  if (killed) result.err += "(no answer within " + std::to_string(kCommandTimeout.count()) + " s)";
  return result;
}

std::string trim(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return {};
  return s.substr(first, s.find_last_not_of(" \t\r\n") - first + 1);
}

/// `s` as one word for bash.
std::string shellQuoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

/// What a command printed to stderr (else stdout), for a reason.
std::string commandMessage(const CommandResult& r) {
  std::string text = trim(r.err.empty() ? r.out : r.err);
  if (text.size() > 500) text = text.substr(0, 500) + "...";
  return text.empty() ? "exit code " + std::to_string(r.exitCode) : text;
}

/// Slurm's final job states (squeue --states=all lists them for MinJobAge seconds after the end).
bool isFinalSlurmState(const std::string& s) {
  return s == "COMPLETED" || s == "CANCELLED" || s == "FAILED" || s == "TIMEOUT" || s == "NODE_FAIL" ||
         s == "PREEMPTED" || s == "BOOT_FAIL" || s == "DEADLINE" || s == "OUT_OF_MEMORY" ||
         s == "SPECIAL_EXIT" || s == "REVOKED";
}

/// Ends in which the job has done nothing wrong and resumes from its checkpoint on another try.
bool isRequeueableSlurmState(const std::string& s) {
  return s == "TIMEOUT" || s == "NODE_FAIL" || s == "PREEMPTED" || s == "BOOT_FAIL";
}

std::optional<int> readExitCode(const std::filesystem::path& file) {
  std::ifstream in(file);
  int code = 0;
  if (in >> code) return code;
  return std::nullopt;
}

std::string solverExitText(std::optional<int> code) {
  if (!code) return "the solver left no exit code (killed with its batch shell)";
  switch (*code) {
    case exit_code::invalid_input: return "the solver rejected the job (exit 2)";
    case exit_code::run_failed: return "the run failed (exit 3)";
    case exit_code::cancelled: return "the solver checkpointed and stopped on SIGTERM (exit 130)";
    case 127: return "the solver could not be executed on the node (exit 127)";
    default: return "the solver exited with code " + std::to_string(*code);
  }
}

std::string batchScriptName() { return "slurm-job.sh"; }
std::string exitFileName(const std::string& slurmJobId) { return "slurm-" + slurmJobId + ".exit"; }
std::string termFileName(const std::string& slurmJobId) { return "slurm-" + slurmJobId + ".term"; }
std::string slurmJobName(const std::string& id, int attempt) {
  return "rcfd-" + id + "-" + std::to_string(attempt);
}

/// The batch script: runs the solver in the background so that the shell can pass Slurm's SIGTERM on
/// (a shell runs its trap only between commands), and records the solver's exit code for the server.
std::string batchScript(const ServerConfig& config, const JobRecord& job, int attempt,
                        const std::vector<std::string>& sbatchArgs) {
  const std::string dir = shellQuoted(config.jobDir(job.id).string());
  const std::filesystem::path solverPath =
      config.slurm.solverPath.empty() ? config.solverPath : config.slurm.solverPath;
  std::string submitted;
  for (const auto& a : sbatchArgs) submitted += " " + shellQuoted(a);
  std::ostringstream s;
  s << "#!/bin/bash\n"
    << "# rcfd-server's " << job.kind << " job " << job.id << ", attempt " << attempt
    << " (docs/cluster.md). Submitted with:\n#   sbatch" << submitted << " " << batchScriptName() << "\n"
    << "# progress.jsonl: the solver's progress lines; solver.log: its log; slurm-<job id>.exit: its exit\n"
    << "# code; slurm-<job id>.term: this shell got SIGTERM (a cancel, or Slurm's warning ahead of the time\n"
    << "# limit) and passed it on, so that the solver checkpoints.\n"
    << "export OMP_NUM_THREADS=\"${SLURM_CPUS_PER_TASK:-1}\"\n"
    << "cd " << dir << " || exit 1\n"
    << "echo \"=== attempt " << attempt << " of " << job.owner
    << "'s job in Slurm job $SLURM_JOB_ID on $(hostname) ===\" >> solver.log\n"
    << shellQuoted(solverPath.string()) << " run job.json --out " << dir
    << " --progress-json >> progress.jsonl 2>> solver.log < /dev/null &\n"
    << "solver=$!\n"
    << "trap 'touch \"slurm-$SLURM_JOB_ID.term\"; kill -TERM \"$solver\" 2>/dev/null' TERM\n"
    << "# wait returns early when the trap has run: wait again until the solver has ended.\n"
    << "while :; do\n"
    << "  wait \"$solver\"; code=$?\n"
    << "  kill -0 \"$solver\" 2>/dev/null || break\n"
    << "done\n"
    << "echo \"$code\" > \"slurm-$SLURM_JOB_ID.exit.tmp\" && mv \"slurm-$SLURM_JOB_ID.exit.tmp\" \"slurm-$SLURM_JOB_ID.exit\"\n"
    << "exit \"$code\"\n";
  return s.str();
}

std::string currentUser() {
  if (const passwd* pw = ::getpwuid(::geteuid()); pw && pw->pw_name) return pw->pw_name;
  return std::to_string(::geteuid());
}

}  // namespace

SlurmExecutor::SlurmExecutor(JobStore& store, const ServerConfig& config)
    : store_(store), config_(config), user_(currentUser()) {}

SlurmExecutor::~SlurmExecutor() { shutdown(); }

void SlurmExecutor::follow(const std::string& id, Followed followed) {
  followed_[id] = std::move(followed);
  busy_ = static_cast<int>(followed_.size());
}

void SlurmExecutor::start() {
  for (const auto& job : store_.unfinished()) {
    Followed followed;
    followed.slurmJobId = job.slurmJobId;
    followed.slurmJobName = slurmJobName(job.id, job.attempt);
    follow(job.id, followed);
    if (job.state == state::cancelling) cancelRequests_.insert(job.id);
  }
  std::cerr << "rcfd-server: Slurm executor: following " << followed_.size()
            << " job(s) already in Slurm; squeue every " << config_.slurm.pollInterval.count() << " s\n";
  thread_ = std::thread(&SlurmExecutor::loop, this);
}

void SlurmExecutor::wake() {
  {
    std::lock_guard lock(mutex_);
    pending_ = true;
  }
  wake_.notify_all();
}

void SlurmExecutor::terminate(const std::string& id) {
  {
    std::lock_guard lock(mutex_);
    cancelRequests_.insert(id);
    pending_ = true;
  }
  wake_.notify_all();
}

void SlurmExecutor::shutdown() {
  std::lock_guard once(shutdownMutex_);
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void SlurmExecutor::loop() {
  auto nextPoll = std::chrono::steady_clock::now();
  for (;;) {
    {
      std::unique_lock lock(mutex_);
      wake_.wait_until(lock, nextPoll, [&] { return stopping_ || pending_; });
      if (stopping_) return;
      pending_ = false;
    }
    try {
      sendCancels();
      submitQueued();
      if (std::chrono::steady_clock::now() >= nextPoll) {
        poll();
        nextPoll = std::chrono::steady_clock::now() + config_.slurm.pollInterval;
      }
    } catch (const std::exception& e) {
      // A store error (disk full) must not end the thread: the jobs are still in Slurm.
      std::cerr << "rcfd-server: Slurm executor: " << e.what() << "\n";
      nextPoll = std::chrono::steady_clock::now() + config_.slurm.pollInterval;
    }
  }
}

void SlurmExecutor::submitQueued() {
  int free = config_.slurm.maxJobs - static_cast<int>(followed_.size());
  if (free <= 0) return;
  for (const auto& job : store_.queued(256)) {
    if (free <= 0) break;
    {
      std::lock_guard lock(mutex_);
      if (stopping_) return;
    }
    if (!databaseReady(store_, config_, job)) continue;
    submit(job);
    --free;
  }
}

void SlurmExecutor::submit(const JobRecord& job) {
  namespace fs = std::filesystem;
  const int attempt = job.attempt + 1;
  const std::string name = slurmJobName(job.id, attempt);
  if (!store_.markStarted(job.id, "submitting to Slurm as " + name)) return;  // cancelled meanwhile
  const fs::path dir = config_.jobDir(job.id);
  const auto& slurm = config_.slurm;
  std::vector<std::string> args = {"--job-name=" + name,
                                   "--output=" + (dir / "slurm-%j.out").string(),
                                   "--chdir=" + dir.string(),
                                   "--ntasks=1",
                                   "--cpus-per-task=" + std::to_string(slurm.cpusPerJob),
                                   // Requeues are the server's: Slurm's own would rerun a job the server
                                   // has already ended, under the same id.
                                   "--no-requeue",
                                   "--open-mode=append"};
  if (slurm.signalLead.count() > 0) args.push_back("--signal=B:TERM@" + std::to_string(slurm.signalLead.count()));
  if (!slurm.partition.empty()) args.push_back("--partition=" + slurm.partition);
  if (!slurm.account.empty()) args.push_back("--account=" + slurm.account);
  if (auto it = slurm.timeLimits.find(job.kind); it != slurm.timeLimits.end()) args.push_back("--time=" + it->second);
  args.insert(args.end(), slurm.extraArguments.begin(), slurm.extraArguments.end());

  Followed followed;
  followed.slurmJobName = name;
  std::string failure;
  try {
    writeJobFile(store_, config_, job);
    std::error_code ec;
    if (fs::exists(dir / "solver.log", ec)) followed.logStart = fs::file_size(dir / "solver.log", ec);
    const fs::path script = dir / batchScriptName();
    {
      std::ofstream out(script);
      out << batchScript(config_, job, attempt, args);
      if (!out) throw std::runtime_error("cannot write " + script.string());
    }
    fs::permissions(script, fs::perms::owner_all);
    std::vector<std::string> command = {"sbatch", "--parsable"};
    command.insert(command.end(), args.begin(), args.end());
    command.push_back(script.string());
    const auto r = runCommand(command);
    // --parsable prints "JOBID" or "JOBID;CLUSTER".
    followed.slurmJobId = trim(r.out.substr(0, r.out.find(';')));
    if (r.exitCode != 0 || followed.slurmJobId.empty() ||
        followed.slurmJobId.find_first_not_of("0123456789") != std::string::npos)
      failure = "sbatch failed: " + commandMessage(r);
  } catch (const std::exception& e) {
    failure = std::string("could not prepare the Slurm job: ") + e.what();
  }
  if (!failure.empty()) {
    if (!store_.transition(job.id, state::running, state::failed, {}, failure))
      store_.transition(job.id, state::cancelling, state::cancelled, "cancelled before it reached Slurm");
    return;
  }
  store_.setSlurmJobId(job.id, followed.slurmJobId);
  follow(job.id, std::move(followed));
}

void SlurmExecutor::sendCancels() {
  std::set<std::string> requests;
  {
    std::lock_guard lock(mutex_);
    requests.swap(cancelRequests_);
  }
  const auto now = std::chrono::steady_clock::now();
  for (auto& [id, f] : followed_) {
    if (f.slurmJobId.empty()) {  // not found in Slurm yet: the cancel waits for the next poll
      if (requests.count(id)) {
        std::lock_guard lock(mutex_);
        cancelRequests_.insert(id);
      }
      continue;
    }
    if (requests.count(id) && !f.cancelSent) {
      // SIGTERM to the batch shell, which passes it to the solver: it checkpoints and exits 130. A job
      // still pending in Slurm has nothing to checkpoint and is simply cancelled.
      auto r = f.slurmState == "PENDING" ? runCommand({"scancel", f.slurmJobId})
                                         : runCommand({"scancel", "--batch", "--signal=TERM", f.slurmJobId});
      // Refused (the job is not running: pending since the last poll): cancelled outright.
      if (r.exitCode != 0 && f.slurmState != "PENDING") r = runCommand({"scancel", f.slurmJobId});
      if (r.exitCode != 0)
        std::cerr << "rcfd-server: scancel of Slurm job " << f.slurmJobId << " (job " << id
                  << "): " << commandMessage(r) << "\n";
      f.cancelSent = true;
      f.cancelSentAt = now;
    } else if (f.cancelSent && !f.killSent && now - f.cancelSentAt > config_.cancelGrace) {
      runCommand({"scancel", f.slurmJobId});
      f.killSent = true;
    }
  }
}

void SlurmExecutor::readProgress(const std::string& id, Followed& followed) {
  namespace fs = std::filesystem;
  const fs::path file = config_.jobDir(id) / "progress.jsonl";
  std::error_code ec;
  const auto size = fs::file_size(file, ec);
  if (ec || size == followed.progressBytes) return;
  followed.progressBytes = size;
  std::ifstream in(file, std::ios::binary);
  constexpr std::uintmax_t kTail = 16 * 1024;  // the last line is all that counts
  in.seekg(static_cast<std::streamoff>(size > kTail ? size - kTail : 0));
  std::string line;
  nlohmann::json latest;
  while (std::getline(in, line)) {
    if (in.eof()) break;  // a line the solver is still writing
    auto parsed = nlohmann::json::parse(line, nullptr, false);
    if (parsed.is_object() && parsed.contains("fraction")) latest = std::move(parsed);
  }
  if (!latest.is_null()) storeProgress(store_, id, latest);
}

void SlurmExecutor::poll() {
  if (followed_.empty()) return;
  const auto r = runCommand({"squeue", "--noheader", "--states=all", "--user=" + user_, "--format=%i|%T|%j"});
  if (r.exitCode != 0) {
    if (!squeueFailing_)
      std::cerr << "rcfd-server: squeue failed (jobs stay as they are until it answers): " << commandMessage(r) << "\n";
    squeueFailing_ = true;
    return;
  }
  squeueFailing_ = false;
  std::map<std::string, std::string> states, idsByName;
  std::istringstream lines(r.out);
  for (std::string line; std::getline(lines, line);) {
    const auto bar = line.find('|');
    const auto bar2 = bar == std::string::npos ? bar : line.find('|', bar + 1);
    if (bar2 == std::string::npos) continue;
    const std::string slurmJobId = trim(line.substr(0, bar));
    states[slurmJobId] = trim(line.substr(bar + 1, bar2 - bar - 1));
    idsByName[trim(line.substr(bar2 + 1))] = slurmJobId;
  }
  std::vector<std::string> ended;
  for (auto& [id, f] : followed_) {
    if (f.slurmJobId.empty()) {
      if (const auto named = idsByName.find(f.slurmJobName); named != idsByName.end()) {
        f.slurmJobId = named->second;
        store_.setSlurmJobId(id, f.slurmJobId);
      } else {
        if (++f.pollsUnlisted >= kPollsBeforeForgotten) {
          notInSlurm(id);
          ended.push_back(id);
        }
        continue;
      }
    }
    readProgress(id, f);
    const auto it = states.find(f.slurmJobId);
    if (it != states.end()) {
      f.pollsUnlisted = 0;
      f.slurmState = it->second;
      if (isFinalSlurmState(f.slurmState)) {
        finish(id, f, f.slurmState);
        ended.push_back(id);
      }
      continue;
    }
    // Not listed: ended longer than MinJobAge ago (a server that was down meanwhile); its exit file says how.
    if (++f.pollsUnlisted >= kPollsBeforeForgotten) {
      finish(id, f, {});
      ended.push_back(id);
    }
  }
  for (const auto& id : ended) followed_.erase(id);
  busy_ = static_cast<int>(followed_.size());
  if (!ended.empty()) wake();  // slots are free: submit what is queued
}

void SlurmExecutor::notInSlurm(const std::string& id) {
  if (!store_.transition(id, state::running, state::queued,
                         "the server stopped before the job reached Slurm; it is submitted again"))
    store_.transition(id, state::cancelling, state::cancelled,
                      "the server stopped while the job was cancelling, before it reached Slurm");
}

void SlurmExecutor::finish(const std::string& id, Followed& f, const std::string& slurmState) {
  namespace fs = std::filesystem;
  const fs::path dir = config_.jobDir(id);
  f.progressBytes = 0;
  readProgress(id, f);  // the last line, even if it came after the last poll
  const auto code = readExitCode(dir / exitFileName(f.slurmJobId));
  std::error_code ec;
  const bool gotTerm = fs::exists(dir / termFileName(f.slurmJobId), ec);
  const bool checkpoint = fs::exists(dir / "checkpoint.h5", ec);
  const std::string slurmJob = "Slurm job " + f.slurmJobId;
  const std::string ended = slurmState.empty() ? slurmJob + " is no longer listed by squeue"
                                                : slurmJob + " ended " + slurmState;
  std::string tail = logTail(dir / "solver.log", static_cast<std::streamoff>(f.logStart));
  const auto withTail = [&](std::string reason) { return tail.empty() ? reason : reason + ": " + tail; };

  // Compare-and-set: a cancel may move the job from RUNNING to CANCELLING between read and write.
  for (int tries = 0; tries < 3; ++tries) {
    const auto current = store_.job(id);
    if (!current || current->state == state::queued || state::isFinal(current->state)) return;
    const std::string from = current->state;
    if (code == exit_code::success) {
      storeSucceeded(store_, config_, id, from);
      return;
    }
    if (from == state::cancelling) {
      const std::string reason =
          code == exit_code::cancelled
              ? (checkpoint ? "the solver checkpointed and stopped"
                            : "the solver stopped before its first checkpoint; a retry starts from the beginning")
              : ended + " after the cancel (" + solverExitText(code) + ")";
      if (store_.transition(id, from, state::cancelled, reason)) return;
      continue;
    }
    if (slurmState == "CANCELLED") {
      if (store_.transition(id, from, state::cancelled,
                            slurmJob + " was cancelled in Slurm, outside the server" +
                                (checkpoint ? "; a retry resumes from its checkpoint" : "")))
        return;
      continue;
    }
    // The solver checkpointed on a SIGTERM nobody in the server asked for: Slurm's warning ahead of the
    // time limit (--signal), or an administrator's. Either way the job resumes where it stopped.
    const bool stoppedToResume = code == exit_code::cancelled && gotTerm;
    if (isRequeueableSlurmState(slurmState) || stoppedToResume) {
      const std::string what = isRequeueableSlurmState(slurmState)
                                   ? ended
                                   : ended + " after the solver checkpointed on SIGTERM (the time limit's warning)";
      if (current->attempt <= config_.slurm.requeues) {
        if (store_.transition(id, from, state::queued,
                              what + "; submitted again to resume from its checkpoint (requeue " +
                                  std::to_string(current->attempt) + " of " +
                                  std::to_string(config_.slurm.requeues) + ")"))
          return;
        continue;
      }
      if (store_.transition(id, from, state::failed, {},
                            what + "; not submitted again after " + std::to_string(config_.slurm.requeues) +
                                " requeue(s) (--slurm-requeues)"))
        return;
      continue;
    }
    const std::string reason =
        slurmState.empty() && !code ? ended + " and left no exit code" : ended + " (" + solverExitText(code) + ")";
    if (store_.transition(id, from, state::failed, {}, withTail(reason))) return;
  }
}

}  // namespace rcfd::server
