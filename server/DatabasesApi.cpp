#include "DatabasesApi.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <iostream>
#include <thread>

#include "ChildSignals.hpp"
#include "Ids.hpp"
#include "Problem.hpp"
#include "fields/FieldDatabase.hpp"

namespace rcfd::server {

namespace {
// Validation reads frames through a bounded cache instead of loading a large upload into RAM.
constexpr std::int64_t kValidationCacheBytes = 64ll << 20;
constexpr std::size_t kMaxReportBytes = 1u << 20;

/// What the validating child said about an upload.
struct CheckOutcome {
  nlohmann::json report;     ///< its JSON line (an object), when it gave one
  std::string failure;       ///< otherwise why there is none: the file's fault (a crash, a time-out)
  bool serverFault = false;  ///< ... or the server's (no pipe, no fork, no exec)
};

/// Runs `rcfd-server --check-uploaded-database FILE` (this program, as /proc/self/exe) and waits for
/// its report, killing it after `limit`. HDF5 reads a damaged file's heap and B-tree addresses as
/// given: it can crash (SIGSEGV) or loop forever on one, and neither may happen in the server.
CheckOutcome checkInChild(const std::filesystem::path& file, std::chrono::seconds limit) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) return {{}, std::string("cannot create a pipe: ") + std::strerror(errno), true};
  const std::string self = "/proc/self/exe", flag(kCheckDatabaseArgument), path = file.string();
  std::vector<const char*> argv = {self.c_str(), flag.c_str(), path.c_str(), nullptr};
  const pid_t parent = ::getpid();
  const sigset_t previous = blockAllSignals();  // ChildSignals.hpp
  const pid_t pid = ::fork();
  if (pid == 0) {
    // Child: only async-signal-safe calls until exec.
    defaultSignalsInChild(false);
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);  // the server gone: nobody waits for the answer
    if (::getppid() != parent) ::_exit(127);
    const int devnull = ::open("/dev/null", O_RDWR);
    ::dup2(devnull, 0);
    ::dup2(fds[1], 1);
    ::dup2(devnull, 2);
    ::close_range(3, ~0U, 0);  // no socket of the server's stays open in the child
    ::execv(argv[0], const_cast<char* const*>(argv.data()));
    ::_exit(127);
  }
  ::pthread_sigmask(SIG_SETMASK, &previous, nullptr);
  ::close(fds[1]);
  if (pid < 0) {
    ::close(fds[0]);
    return {{}, std::string("fork failed: ") + std::strerror(errno), true};
  }
  std::string out;
  bool timedOut = false;
  const auto deadline = std::chrono::steady_clock::now() + limit;
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
    if (left <= 0) {
      ::kill(pid, SIGKILL);
      timedOut = true;
      break;
    }
    pollfd ready{fds[0], POLLIN, 0};
    const int n = ::poll(&ready, 1, int(std::min<long long>(left, 1000)));
    if (n == 0 || (n < 0 && errno == EINTR)) continue;
    char chunk[4096];
    const ssize_t got = n < 0 ? -1 : ::read(fds[0], chunk, sizeof chunk);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) break;  // end of the report (or a pipe error: the status tells)
    if (out.size() < kMaxReportBytes) out.append(chunk, std::size_t(got));
  }
  ::close(fds[0]);
  // The report ended; the child should exit now, but the deadline holds for that too.
  int status = 0;
  for (;;) {
    const pid_t done = ::waitpid(pid, &status, timedOut ? 0 : WNOHANG);
    if (done == pid || (done < 0 && errno != EINTR)) break;
    if (done != 0) continue;
    if (std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    } else {
      ::kill(pid, SIGKILL);
      timedOut = true;
    }
  }
  if (timedOut) return {{}, "its validation did not end within " + std::to_string(limit.count()) + " s"};
  if (WIFSIGNALED(status))
    return {{}, "reading it crashed the HDF5 library (signal " + std::to_string(WTERMSIG(status)) +
                    "): the file is damaged"};
  auto report = nlohmann::json::parse(out, nullptr, false);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || !report.is_object())
    return {{}, "the validating process ended with status " + std::to_string(status) + " and no report", true};
  return {std::move(report), {}, false};
}

nlohmann::json toJson(const DatabaseRecord& db) {
  return {{"id", db.id},
          {"frames", db.frames},
          {"bytes", db.bytes},
          {"created_at", db.createdAt},
          {"owner", db.owner},
          {"links", {{"self", "/v1/databases/" + db.id}}}};
}
}  // namespace

std::filesystem::path DatabasesApi::temporaryUploadPath() const {
  auto dir = config_.databaseDir() / "incoming";
  std::filesystem::create_directories(dir);
  return dir / (newId() + ".h5.part");
}

StringResponse DatabasesApi::accept(const std::filesystem::path& file, const Target& target,
                                    const Caller& caller) {
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(file, ec);
  if (ec || bytes == 0) {
    std::filesystem::remove(file, ec);
    return problem(http::status::bad_request, "empty-upload", "Empty upload",
                   "the request body must be an HDF5 field database (docs/formats.md)", target.path);
  }
  const auto refuse = [&](StringResponse res) {
    std::filesystem::remove(file, ec);
    return res;
  };
  const CheckOutcome check = checkInChild(file, config_.uploadCheckTimeout);
  if (check.serverFault)
    return refuse(problem(http::status::internal_server_error, "validation-failed", "Validation failed",
                          "the upload could not be validated: " + check.failure, target.path));
  if (!check.failure.empty())
    return refuse(problem(http::status::unprocessable_entity, "invalid-database", "Invalid field database",
                          "the upload is not a readable field database: " + check.failure, target.path));
  const auto& report = check.report;
  if (const auto list = report.find("violations"); list != report.end() && list->is_array() && !list->empty()) {
    std::vector<Violation> violations;
    for (const auto& v : *list) violations.push_back({v.value("pointer", ""), v.value("message", "")});
    // The source is "upload", not the server's temporary file name.
    return refuse(invalidInput(InputError("upload", std::move(violations)), target.path));
  }
  if (report.contains("error") || !report.contains("frames") || !report["frames"].is_number_integer()) {
    std::string what = report.value("error", "no frame count in the validation report");
    for (auto at = what.find(file.string()); at != std::string::npos; at = what.find(file.string()))
      what.replace(at, file.string().size(), "upload");
    return refuse(problem(http::status::unprocessable_entity, "invalid-database", "Invalid field database",
                          "the upload is not a readable field database: " + what, target.path));
  }
  DatabaseRecord db;
  db.frames = report["frames"].get<int>();
  db.id = newId();
  db.bytes = static_cast<std::int64_t>(bytes);
  db.path = (config_.databaseDir() / (db.id + ".h5")).string();
  db.createdAt = nowRfc3339();
  db.owner = caller.name;
  std::filesystem::rename(file, db.path, ec);
  if (ec) {
    std::filesystem::remove(file, ec);
    return problem(http::status::internal_server_error, "storage-failed", "Storage failed",
                   "cannot move the upload into " + config_.databaseDir().string(), target.path);
  }
  store_.insertDatabase(db);
  auto res = jsonResponse(http::status::created, toJson(db));
  res.set(http::field::location, "/v1/databases/" + db.id);
  return res;
}

int checkUploadedDatabase(const std::filesystem::path& file) {
  nlohmann::json report;
  try {
    const auto opened = FieldDatabase::open(file.string(), FrameStorage{kValidationCacheBytes});
    // Every frame is read once: a NaN or Inf is refused now (InputError naming the dataset and the
    // frame), not when a spray job reaches that frame hours later.
    const int frames = opened->frameCount();
    for (int i = 0; i < frames; ++i) (void)opened->frame(i);
    report = {{"frames", frames}};
  } catch (const InputError& e) {
    nlohmann::json violations = nlohmann::json::array();
    for (const auto& v : e.violations()) violations.push_back({{"pointer", v.pointer}, {"message", v.message}});
    report = {{"violations", violations}};
  } catch (const std::exception& e) {
    report = {{"error", e.what()}};
  }
  std::cout << jsonText(report) << std::flush;
  return 0;
}

Response DatabasesApi::get(const std::string& id, const Target& target, const Caller& caller) {
  const auto db = store_.database(id);
  if (!db || !caller.mayAccess(db->owner))
    return problem(http::status::not_found, "database-not-found", "Database not found",
                   "there is no uploaded database with id \"" + id + "\"", target.path);
  return jsonResponse(http::status::ok, toJson(*db));
}

Response DatabasesApi::list(const Caller& caller) {
  nlohmann::json items = nlohmann::json::array();
  for (const DatabaseRecord& db : store_.listDatabases(caller.admin ? std::string() : caller.name))
    items.push_back(toJson(db));
  return jsonResponse(http::status::ok, {{"databases", std::move(items)}});
}

}  // namespace rcfd::server
