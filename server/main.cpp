// rcfd-server: the HTTP/JSON job server (docs/contracts.md, docs/api.md). This file reads the command
// line, opens the store, starts the worker pool and the listener, and shuts down on SIGINT/SIGTERM:
// stop accepting, then let running solvers checkpoint (their jobs resume on the next start).

#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/thread_pool.hpp>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string_view>
#include <thread>

#include "Ids.hpp"
#include "JobStore.hpp"
#include "Listener.hpp"
#include "Metrics.hpp"
#include "PageToken.hpp"
#include "Router.hpp"
#include "ServerConfig.hpp"
#include "SlurmExecutor.hpp"
#include "TlsContext.hpp"
#include "Users.hpp"
#include "WorkerPool.hpp"

namespace net = boost::asio;
using namespace rcfd::server;

namespace {

std::string trim(std::string s) {
  const auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return {};
  return s.substr(first, s.find_last_not_of(" \t\r\n") - first + 1);
}

std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// The token from --token-file, else RCFD_TOKEN, else DIR/token (created with a random token).
std::string resolveToken(const std::string& tokenFile, const std::filesystem::path& dataDir) {
  if (!tokenFile.empty()) {
    auto token = trim(readFile(tokenFile));
    if (token.empty()) throw std::runtime_error("--token-file " + tokenFile + " is empty");
    return token;
  }
  if (const char* env = std::getenv("RCFD_TOKEN"); env && *env) return trim(env);
  const auto path = dataDir / "token";
  if (std::filesystem::exists(path)) {
    auto token = trim(readFile(path));
    if (!token.empty()) {
      std::cerr << "rcfd-server: using the token in " << path.string() << "\n";
      return token;
    }
  }
  const std::string token = newId();
  {
    std::ofstream out(path);
    out << token << "\n";
    if (!out) throw std::runtime_error("cannot write " + path.string());
  }
  ::chmod(path.c_str(), 0600);
  std::cerr << "rcfd-server: no token configured; generated one in " << path.string()
            << " (clients: RCFD_TOKEN=$(cat " << path.string() << "))\n";
  return token;
}

net::ip::tcp::endpoint parseListen(const std::string& text) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos) throw std::runtime_error("--listen must be HOST:PORT, got " + text);
  std::string host = text.substr(0, colon);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  const int port = std::stoi(text.substr(colon + 1));
  if (port < 0 || port > 65535) throw std::runtime_error("--listen port must be 0..65535");
  return {net::ip::make_address(host), static_cast<unsigned short>(port)};
}

/// Warns when the data directory lets group or others in: the server makes what it creates there
/// owner-only, but through an open directory older files (a store or job folders made under another
/// umask) stay readable.
void warnIfOpenToOthers(const std::filesystem::path& dataDir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const auto status = fs::status(dataDir, ec);
  if (ec || !fs::is_directory(status)) return;
  const auto open = status.permissions() & (fs::perms::group_all | fs::perms::others_all);
  if (open == fs::perms::none) return;
  char mode[8];
  std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(status.permissions() & fs::perms::mask));
  std::cerr << "rcfd-server: warning: data directory " << dataDir.string() << " is accessible to "
            << ((open & fs::perms::others_all) != fs::perms::none ? "others" : "its group") << " (mode "
            << mode << "): jobs, results and the job store can be read through it; chmod 700 "
            << dataDir.string() << "\n";
}

std::filesystem::path defaultSolver() {
  std::error_code ec;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::filesystem::path("rcfd-solve") : self.parent_path() / "rcfd-solve";
}

}  // namespace

int main(int argc, char** argv) {
  // The child that validates an upload (DatabasesApi::accept): HDF5 may crash or loop on a damaged
  // file, so the server never opens an uploaded file itself.
  if (argc == 3 && std::string_view(argv[1]) == kCheckDatabaseArgument) return checkUploadedDatabase(argv[2]);
  CLI::App app{"rcfd-server: the rcfd job server (REST under /v1, docs/api.md)"};
  ServerConfig config;
  std::string dataDir, listen = "127.0.0.1:8080", tokenFile, usersFile, tlsCert, tlsKey, solver;
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  config.workers = static_cast<int>(std::max(1u, cores / 2));
  int ioThreads = 2;
  std::uint64_t maxUpload = config.uploadLimit, maxBody = config.jsonBodyLimit;
  int graceSeconds = static_cast<int>(config.shutdownGrace.count());
  app.add_option("--data-dir", dataDir, "directory for rcfd.sqlite, jobs/ and databases/")->required();
  app.add_option("--listen", listen, "HOST:PORT to listen on (port 0 picks a free one)")->capture_default_str();
  auto* tokenOption =
      app.add_option("--token-file", tokenFile, "file holding the bearer token (else RCFD_TOKEN, else DIR/token)");
  app.add_option("--users-file", usersFile,
                 "named users instead of one token: lines NAME ROLE SHA256HEX (ROLE user or admin; the "
                 "SHA-256 of the user's token: printf %s TOKEN | sha256sum)")
      ->excludes(tokenOption);
  auto* certOption = app.add_option("--tls-cert", tlsCert, "PEM certificate chain: the server speaks HTTPS");
  auto* keyOption = app.add_option("--tls-key", tlsKey, "PEM private key of --tls-cert (unencrypted)");
  certOption->needs(keyOption);
  keyOption->needs(certOption);
  app.add_option("--workers", config.workers, "concurrent solver processes; 0 keeps jobs queued")->capture_default_str()
      ->check(CLI::Range(0, 1024));
  app.add_option("--worker-nice", config.workerNice,
                 "niceness added to solver processes, so HTTP answers do not wait behind them")
      ->capture_default_str()->check(CLI::Range(0, 19));
  app.add_option("--solver", solver, "rcfd-solve executable (default: beside rcfd-server)");
  std::string importRoot;
  app.add_option("--import-root", importRoot,
                 "directory of OpenFOAM cases that import jobs may read (their case_dir is relative to it); "
                 "without it the server takes no import job");
  app.add_option("--io-threads", ioThreads, "threads serving HTTP")->capture_default_str()->check(CLI::Range(1, 64));
  app.add_option("--max-body-bytes", maxBody, "limit of a JSON request body")->capture_default_str();
  app.add_option("--max-upload-bytes", maxUpload, "limit of a database upload")->capture_default_str();
  app.add_option("--shutdown-grace", graceSeconds, "seconds solvers get to checkpoint on shutdown")->capture_default_str();
  int cancelGrace = static_cast<int>(config.cancelGrace.count());
  app.add_option("--cancel-grace", cancelGrace, "seconds a cancelled solver gets to checkpoint before it is killed")
      ->capture_default_str()->check(CLI::Range(1, 86400));
  app.add_option("--auto-retries", config.autoRetries,
                 "times a job whose solver is killed from outside the server (SIGKILL, as the kernel's out-of-memory "
                 "killer does) is queued again to resume from its checkpoint")
      ->capture_default_str()->check(CLI::Range(0, 100));
  int idleBeforeToken = static_cast<int>(config.idleBeforeToken.count());
  app.add_option("--idle-before-token", idleBeforeToken,
                 "seconds a connection may wait for its first request with a token before it is closed")
      ->capture_default_str()->check(CLI::Range(1, 3600));
  auto* maxConnections = app.add_option("--max-connections", config.maxConnections,
                                        "open connections in total (default: 1024, at most the descriptor limit less 64)")
      ->capture_default_str()->check(CLI::Range(1, 1000000));
  app.add_option("--max-connections-per-peer", config.maxConnectionsPerPeer, "open connections from one address")
      ->capture_default_str()->check(CLI::Range(1, 1000000));
  int uploadCheckTimeout = static_cast<int>(config.uploadCheckTimeout.count());
  app.add_option("--upload-check-timeout", uploadCheckTimeout,
                 "seconds the validation of an uploaded database may take before it is stopped (422)")
      ->capture_default_str()->check(CLI::Range(1, 86400));
  app.add_option("--executor", config.executor,
                 "where jobs run: local (solver processes on this machine) or slurm (batch jobs on a Slurm "
                 "cluster that shares the data directory; docs/cluster.md)")
      ->capture_default_str()->check(CLI::IsMember({"local", "slurm"}));
  std::vector<std::string> slurmTimes;
  std::string slurmSolver;
  int slurmPoll = static_cast<int>(config.slurm.pollInterval.count());
  int slurmLead = static_cast<int>(config.slurm.signalLead.count());
  app.add_option("--slurm-partition", config.slurm.partition, "sbatch --partition (default: the cluster's)");
  app.add_option("--slurm-account", config.slurm.account, "sbatch --account (default: the user's)");
  app.add_option("--slurm-time", slurmTimes,
                 "KIND=LIMIT: sbatch --time for jobs of that kind (database, calibration, spray), in Slurm's "
                 "formats (minutes, H:MM:SS, D-HH); repeat per kind; default: the partition's limit");
  app.add_option("--slurm-cpus", config.slurm.cpusPerJob, "CPUs per job (sbatch --cpus-per-task; the solver's threads)")
      ->capture_default_str()->check(CLI::Range(1, 4096));
  app.add_option("--slurm-sbatch-arg", config.slurm.extraArguments,
                 "one more sbatch argument, as --slurm-sbatch-arg=--qos=long; repeatable")->allow_extra_args(false);
  app.add_option("--slurm-solver", slurmSolver, "rcfd-solve as the compute nodes see it (default: --solver)");
  app.add_option("--slurm-poll-interval", slurmPoll, "seconds between two squeue calls (one for all jobs)")
      ->capture_default_str()->check(CLI::Range(1, 3600));
  app.add_option("--slurm-requeues", config.slurm.requeues,
                 "times a job Slurm ends by TIMEOUT, NODE_FAIL or PREEMPTED is submitted again to resume from its checkpoint")
      ->capture_default_str()->check(CLI::Range(0, 100));
  app.add_option("--slurm-signal-lead", slurmLead,
                 "seconds before the time limit at which Slurm sends SIGTERM, so that the solver checkpoints (0: none)")
      ->capture_default_str()->check(CLI::Range(0, 65535));
  app.add_option("--slurm-max-jobs", config.slurm.maxJobs, "jobs in Slurm at once; more wait QUEUED in the server")
      ->capture_default_str()->check(CLI::Range(1, 1000000));
  CLI11_PARSE(app, argc, argv);

  try {
    std::signal(SIGPIPE, SIG_IGN);
    // Jobs, results and the store belong to the users who submitted them: whatever the server and its
    // solvers create is owner-only (directories 0700, files 0600), whatever umask it was started with.
    ::umask(077);
    config.dataDir = std::filesystem::absolute(dataDir);
    warnIfOpenToOthers(config.dataDir);
    std::filesystem::create_directories(config.dataDir / "jobs");
    std::filesystem::create_directories(config.databaseDir());
    if (usersFile.empty()) {
      config.users = UserDirectory::singleToken(resolveToken(tokenFile, config.dataDir));
    } else {
      std::string warning;
      config.users = UserDirectory::load(usersFile, warning);
      if (!warning.empty()) std::cerr << "rcfd-server: warning: " << warning << "\n";
      std::cerr << "rcfd-server: " << config.users.size() << " user(s) from " << usersFile << "\n";
    }
    std::unique_ptr<net::ssl::context> tls;
    if (!tlsCert.empty()) {
      std::string warning;
      tls = serverTlsContext(tlsCert, tlsKey, warning);
      if (!warning.empty()) std::cerr << "rcfd-server: warning: " << warning << "\n";
    }
    config.pageTokenKey = pageTokenKey(config.dataDir);
    config.solverPath = solver.empty() ? defaultSolver() : std::filesystem::absolute(solver);
    if (!importRoot.empty()) config.importRoot = std::filesystem::weakly_canonical(std::filesystem::absolute(importRoot));
    config.jsonBodyLimit = maxBody;
    config.uploadLimit = maxUpload;
    config.shutdownGrace = std::chrono::seconds(graceSeconds);
    config.idleBeforeToken = std::chrono::seconds(idleBeforeToken);
    config.cancelGrace = std::chrono::seconds(cancelGrace);
    config.uploadCheckTimeout = std::chrono::seconds(uploadCheckTimeout);
    config.slurm.pollInterval = std::chrono::seconds(slurmPoll);
    config.slurm.signalLead = std::chrono::seconds(slurmLead);
    config.slurm.solverPath = slurmSolver.empty() ? config.solverPath : std::filesystem::path(slurmSolver);
    for (const auto& entry : slurmTimes) {
      const auto eq = entry.find('=');
      if (eq == std::string::npos || eq == 0 || eq + 1 == entry.size())
        throw std::runtime_error("--slurm-time must be KIND=LIMIT, got " + entry);
      config.slurm.timeLimits[entry.substr(0, eq)] = entry.substr(eq + 1);
    }
    // Connections beyond the descriptor limit would make accept fail: keep 64 for SQLite, logs, solvers.
    if (rlimit files{}; maxConnections->count() == 0 && ::getrlimit(RLIMIT_NOFILE, &files) == 0 &&
                        files.rlim_cur != RLIM_INFINITY)
      config.maxConnections = std::max(1, std::min(config.maxConnections, int(files.rlim_cur) - 64));
    if (config.executor == "local" && config.workers > 0 && ::access(config.solverPath.c_str(), X_OK) != 0)
      std::cerr << "rcfd-server: warning: solver " << config.solverPath.string()
                << " is not executable; jobs will fail (use --solver)\n";

    JobStore store((config.dataDir / "rcfd.sqlite").string());
    std::unique_ptr<JobExecutor> executor;
    if (config.executor == "slurm") executor = std::make_unique<SlurmExecutor>(store, config);
    else executor = std::make_unique<WorkerPool>(store, config);
    JobExecutor& pool = *executor;
    Metrics metrics;
    Router router(store, pool, metrics, config);
    net::io_context ioc(ioThreads);
    net::thread_pool blocking(2);
    auto listener = std::make_shared<Listener>(ioc, parseListen(listen), router, blocking, tls.get());
    // Signals are caught before the listening line is printed, so a supervisor that reads it can
    // always stop the server gracefully.
    // Shutdown: refuse new connections, keep answering the open ones (status polls see the jobs
    // go back to QUEUED) while the solvers checkpoint, and only then stop the io threads.
    net::signal_set signals(ioc, SIGINT, SIGTERM);
    signals.async_wait([&](const boost::system::error_code& ec, int sig) {
      if (ec) return;
      std::cerr << "rcfd-server: signal " << sig
                << (config.executor == "slurm"
                        ? ": stopping; jobs in Slurm go on, and the next start follows them\n"
                        : ": stopping; running solvers checkpoint and resume on the next start\n");
      listener->stop([&] {
        net::post(blocking, [&] {  // waits up to the grace period: never on an io thread
          pool.shutdown();
          ioc.stop();
        });
      });
    });
    const auto bound = listener->endpoint();
    const std::string host = bound.address().is_v6() ? "[" + bound.address().to_string() + "]"
                                                     : bound.address().to_string();
    std::cout << "listening on " << (tls ? "https" : "http") << "://" << host << ":" << bound.port() << std::endl;
    if (config.executor == "slurm")
      std::cerr << "rcfd-server: data " << config.dataDir.string() << ", jobs run in Slurm (at most "
                << config.slurm.maxJobs << " at once), solver on the nodes " << config.slurm.solverPath.string() << "\n";
    else
      std::cerr << "rcfd-server: data " << config.dataDir.string() << ", " << config.workers
                << " worker slot(s), solver " << config.solverPath.string() << "\n";
    pool.start();
    listener->run();
    // The io threads run until the shutdown handler stops them, even when no connection is open.
    auto keepRunning = net::make_work_guard(ioc);

    std::vector<std::thread> threads;
    for (int i = 1; i < ioThreads; ++i) threads.emplace_back([&ioc] { ioc.run(); });
    ioc.run();
    for (auto& t : threads) t.join();
    pool.shutdown();
    blocking.join();
    std::cerr << "rcfd-server: stopped\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "rcfd-server: error: " << e.what() << "\n";
    return 1;
  }
}
