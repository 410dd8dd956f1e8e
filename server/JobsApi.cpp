#include "JobsApi.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <regex>
#include <utility>

#include "CoverageExport.hpp"
#include "DatabaseRef.hpp"
#include "Ids.hpp"
#include "PageToken.hpp"
#include "Problem.hpp"
#include "JobExecutor.hpp"
#include "scene/SceneJson.hpp"
#include "scene/SceneLoader.hpp"
#include "scene/SchemaValidator.hpp"

namespace rcfd::server {

namespace {

constexpr int kDefaultPageSize = 50;
constexpr int kMaxPageSize = 1000;
constexpr std::size_t kMaxIdempotencyKey = 200;
constexpr const char* kRetryAfterSeconds = "2";
// The .xmf files are the XDMF sidecars through which ParaView opens database.h5 and result.h5.
const char* const kFixedArtifacts[] = {"database.h5", "result.h5", "database.xmf", "result.xmf",
                                       "summary.json", "solver.log", "job.json"};

StringResponse notFound(const std::string& id, const Target& target) {
  return problem(http::status::not_found, "job-not-found", "Job not found",
                 "there is no job with id \"" + id + "\"", target.path);
}

StringResponse notFinished(const JobRecord& job, const Target& target, const std::string& what) {
  return problem(http::status::conflict, "job-not-succeeded", "Job has not succeeded",
                 what + " exists only for SUCCEEDED jobs; job " + job.id + " is " + job.state +
                     (job.error.empty() ? std::string() : " (" + job.error + ")"),
                 target.path);
}

StringResponse badParameter(const std::string& name, const std::string& message,
                            const Target& target) {
  return invalidQueryParameter(name, message, target.path);
}

/// A query value quoted in a message, cut short: the message echoes the request, not a payload.
std::string quotedValue(const std::string& value) {
  constexpr std::size_t kMaxQuoted = 60;
  return "\"" + (value.size() > kMaxQuoted ? value.substr(0, kMaxQuoted) + "..." : value) + "\"";
}

/// A descriptor closed when it goes out of scope.
class Descriptor {
 public:
  explicit Descriptor(int fd) : fd_(fd) {}
  ~Descriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  Descriptor(const Descriptor&) = delete;
  Descriptor& operator=(const Descriptor&) = delete;
  int get() const { return fd_; }
  int release() { return std::exchange(fd_, -1); }

 private:
  int fd_;
};

/// The job's folder opened without following a symlink at jobs/ or at the folder itself: a link
/// planted below the data directory must not make the server serve files from elsewhere. -1 if it
/// is absent or a link.
int openJobFolder(const ServerConfig& config, const std::string& id) {
  const Descriptor data(::open(config.dataDir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (data.get() < 0) return -1;
  const Descriptor jobs(::openat(data.get(), "jobs", O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC));
  if (jobs.get() < 0) return -1;
  return ::openat(jobs.get(), id.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
}

/// A regular file of the job's folder opened for reading; -1 if it is absent, a symlink or anything
/// but a regular file. O_NONBLOCK: opening a FIFO planted there must not block the strand.
int openJobFile(const ServerConfig& config, const std::string& id, const std::string& name) {
  const Descriptor folder(openJobFolder(config, id));
  if (folder.get() < 0) return -1;
  Descriptor file(::openat(folder.get(), name.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC));
  struct stat st {};
  if (file.get() < 0 || ::fstat(file.get(), &st) != 0 || !S_ISREG(st.st_mode)) return -1;
  return file.release();
}

/// A file response streaming an open descriptor (which it then owns).
Response fileResponse(int fd, const std::string& contentType, const std::string& downloadName) {
  FileResponse res{http::status::ok, 11};
  boost::beast::file file;
  file.native_handle(fd);
  boost::beast::error_code ec;
  res.body().reset(std::move(file), ec);
  if (ec) throw std::runtime_error("cannot read " + downloadName + ": " + ec.message());
  res.set(http::field::content_type, contentType);
  res.set(http::field::content_disposition, "attachment; filename=\"" + downloadName + "\"");
  res.prepare_payload();
  return res;
}

/// Replaces, in every string of `node`, a path inside the data directory by the path relative to it.
void relativeToDataDir(nlohmann::json& node, const std::string& dataDirPrefix) {
  if (node.is_string()) {
    const auto& text = node.get_ref<const std::string&>();
    if (text.rfind(dataDirPrefix, 0) == 0) node = text.substr(dataDirPrefix.size());
  } else if (node.is_structured()) {
    for (auto& child : node) relativeToDataDir(child, dataDirPrefix);
  }
}

std::string contentTypeFor(const std::string& name) {
  const auto ext = std::filesystem::path(name).extension().string();
  if (ext == ".h5") return "application/x-hdf5";
  if (ext == ".svg") return "image/svg+xml";
  if (ext == ".xmf") return "application/xml";
  if (ext == ".json") return "application/json";
  return "text/plain; charset=utf-8";
}

}  // namespace

JobsApi::JobsApi(JobStore& store, JobExecutor& pool, const ServerConfig& config)
    : store_(store), pool_(pool), config_(config) {
  store_.setChangeListener([this](const std::string& id) { views_.invalidate(id); });
}

JobsApi::~JobsApi() { store_.setChangeListener({}); }

std::optional<JobRecord> JobsApi::visibleJob(const std::string& id, const Caller& caller) {
  auto job = store_.job(id);
  if (!job || !caller.mayAccess(job->owner)) return std::nullopt;
  return job;
}

bool isArtifactName(const std::string& name) {
  for (const char* fixed : kFixedArtifacts)
    if (name == fixed) return true;
  static const std::regex svg("[A-Za-z0-9][A-Za-z0-9_-]*(\\.[A-Za-z0-9_-]+)*\\.svg");
  return name.size() <= 128 && std::regex_match(name, svg);
}

std::vector<std::string> JobsApi::artifacts(const std::string& id) const {
  std::vector<std::string> names;
  const int folder = openJobFolder(config_, id);
  if (folder < 0) return names;
  DIR* dir = ::fdopendir(folder);
  if (!dir) {
    ::close(folder);
    return names;
  }
  // Listed as artifact() serves them: regular files, symlinks not followed.
  while (const dirent* entry = ::readdir(dir)) {
    const std::string name = entry->d_name;
    struct stat st {};
    if (isArtifactName(name) && ::fstatat(::dirfd(dir), entry->d_name, &st, AT_SYMLINK_NOFOLLOW) == 0 &&
        S_ISREG(st.st_mode))
      names.push_back(name);
  }
  ::closedir(dir);
  std::sort(names.begin(), names.end());
  return names;
}

nlohmann::json JobsApi::toJson(const JobRecord& job, bool withRequest) const {
  const auto orNull = [](const std::string& s) { return s.empty() ? nlohmann::json() : nlohmann::json(s); };
  const auto optNum = [](const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(); };
  const std::string self = "/v1/jobs/" + job.id;
  nlohmann::json j = {
      {"id", job.id},
      {"kind", job.kind},
      {"state", job.state},
      {"owner", job.owner},
      {"progress",
       {{"fraction", job.progress},
        {"sim_time", optNum(job.simTime)},
        {"wall_time", optNum(job.wallTime)},
        {"eta_s", optNum(job.etaS)},
        {"phase", orNull(job.phase)},
        {"phase_fraction", optNum(job.phaseFraction)}}},
      {"database", orNull(job.databaseRef)},
      {"attempt", job.attempt},
      {"error", orNull(job.error)},
      {"created_at", job.createdAt},
      {"started_at", orNull(job.startedAt)},
      {"finished_at", orNull(job.finishedAt)},
      {"updated_at", job.updatedAt},
      {"links",
       {{"self", self},
        {"cancel", self + ":cancel"},
        {"retry", self + ":retry"},
        {"events", self + "/events"},
        {"result", self + "/result"},
        {"coverage", self + "/coverage"}}},
  };
  if (job.state == state::succeeded || job.state == state::failed) j["artifacts"] = artifacts(job.id);
  if (withRequest) j["request"] = nlohmann::json::parse(job.request);
  return j;
}

Response JobsApi::submit(const Request& req, const Target& target, const Caller& caller) {
  // A job is JSON: a form or text body is refused before it is parsed.
  const auto type = req.find(http::field::content_type);
  std::string_view media = type == req.end() ? std::string_view() : std::string_view(type->value().data(), type->value().size());
  const std::string_view sent = media.substr(0, 100);
  media = media.substr(0, media.find(';'));
  while (!media.empty() && media.back() == ' ') media.remove_suffix(1);
  if (!boost::beast::iequals(boost::beast::string_view(media.data(), media.size()), "application/json"))
    return problem(http::status::unsupported_media_type, "unsupported-media-type", "Unsupported media type",
                   "a job is sent as \"Content-Type: application/json\" (got \"" + std::string(sent) + "\")",
                   target.path);
  nlohmann::json document;
  try {
    document = nlohmann::json::parse(req.body());
  } catch (const nlohmann::json::exception& e) {  // syntax, and numbers beyond double range
    return problem(http::status::bad_request, "invalid-json", "Malformed JSON",
                   "the request body is not valid JSON: " + std::string(e.what()), target.path);
  }
  if (document.is_object() && document.contains("scene_file"))
    return invalidInput(
        InputError("job", "/scene_file",
                   "the server reads no files: inline the scene as \"scene\" (rcfd submit does this)"),
        target.path);
  JobSpec spec;
  try {
    spec = loadJob(document, "job");
  } catch (const InputError& e) {
    return invalidInput(e, target.path);
  }
  // The solver opens a file a scene names as the server's user: a job could read any file the server
  // can (its first word lands in the job's error). No such field is taken, inline or patched.
  const nlohmann::json scene = sceneToJson(spec.scene);
  static const std::vector<std::string> filePaths = SchemaValidator::get("scene").filePathPointers();
  for (const std::string& pointer : filePaths) {
    const nlohmann::json::json_pointer at(pointer);
    if (scene.contains(at) && scene[at].is_string() && !scene[at].get<std::string>().empty())
      return invalidInput(InputError("job", "/scene" + pointer,
                                     "the server opens no file a job names (set inline or through "
                                     "/scene_patch): run this scene with rcfd-solve instead"),
                          target.path);
  }
  if (spec.kind == "import") {
    // An import reads a directory by name: only one inside the import root the operator named.
    std::string why;
    if (config_.importRoot.empty()) {
      why = "this server reads no OpenFOAM case (start it with --import-root DIR); or import with "
            "rcfd-solve import-openfoam and upload the database";
    } else if (const auto dir = importCaseDirectory(config_.importRoot, spec.source.at("case_dir").get<std::string>());
               dir.empty()) {
      why = "must name a case directory inside the server's import root, relative to it";
    }
    if (!why.empty()) return invalidInput(InputError("job", "/case_dir", why), target.path);
  }
  if (spec.kind != "database" && spec.kind != "import" && spec.database.empty())
    return invalidInput(InputError("job", "/database",
                                   "required for " + spec.kind +
                                       " jobs: the id of a database job or an uploaded database"),
                        target.path);
  if (!spec.database.empty()) {
    const DatabaseRef ref = resolveDatabaseRef(store_, config_, spec.database, &caller);
    if (ref.status == DatabaseRef::Status::unknown || ref.status == DatabaseRef::Status::failed)
      return invalidInput(InputError("job", "/database", ref.detail), target.path);
  }

  std::string key;
  if (auto it = req.find("Idempotency-Key"); it != req.end()) {
    key = std::string(it->value());
    if (key.empty() || key.size() > kMaxIdempotencyKey)
      return problem(http::status::bad_request, "invalid-idempotency-key", "Invalid Idempotency-Key",
                     "the Idempotency-Key header must have 1 to 200 characters", target.path);
  }
  JobRecord job;
  job.id = newId();
  job.kind = spec.kind;
  job.request = document.dump();
  job.bodyHash = bodyHash(job.request);
  job.idempotencyKey = key;
  job.databaseRef = spec.database;
  job.owner = caller.name;
  const auto inserted = store_.insertJob(job);
  if (!inserted.created && inserted.job.bodyHash != job.bodyHash)
    return problem(http::status::unprocessable_entity, "idempotency-key-reused",
                   "Idempotency-Key reused with a different body",
                   "Idempotency-Key \"" + key + "\" was used for job " + inserted.job.id +
                       " with a different request body",
                   target.path);
  if (inserted.created) pool_.wake();
  auto res = jsonResponse(http::status::accepted, toJson(inserted.job));
  res.set(http::field::location, "/v1/jobs/" + inserted.job.id);
  res.set(http::field::retry_after, kRetryAfterSeconds);
  if (!inserted.created) res.set("Idempotent-Replayed", "true");
  return res;
}

Response JobsApi::list(const Target& target, const Caller& caller) {
  JobFilter filter;
  filter.limit = kDefaultPageSize;
  // A plain user lists their own jobs whatever they ask for; ?owner= narrows an admin's listing.
  filter.owner = caller.admin ? std::string() : caller.name;
  bool othersOnly = false;  // a plain user asked for someone else's jobs: none to show
  if (auto it = target.query.find("owner"); it != target.query.end()) {
    if (caller.admin) filter.owner = it->second;
    else othersOnly = it->second != caller.name;
  }
  if (auto it = target.query.find("state"); it != target.query.end()) {
    if (!state::isValid(it->second))
      return badParameter("state", quotedValue(it->second) +
                                       " is not one of QUEUED, RUNNING, SUCCEEDED, FAILED, "
                                       "CANCELLING, CANCELLED",
                          target);
    filter.state = it->second;
  }
  if (auto it = target.query.find("kind"); it != target.query.end()) {
    const std::vector<std::string>& kinds = jobKinds();
    if (std::find(kinds.begin(), kinds.end(), it->second) == kinds.end()) {
      std::string list;
      for (const auto& k : kinds) list += (list.empty() ? "" : ", ") + k;
      return badParameter("kind", quotedValue(it->second) + " is not one of " + list, target);
    }
    filter.kind = it->second;
  }
  if (auto it = target.query.find("page_size"); it != target.query.end()) {
    int n = 0;
    try {
      std::size_t used = 0;
      n = std::stoi(it->second, &used);
      if (used != it->second.size()) n = 0;
    } catch (...) {
      n = 0;
    }
    if (n < 1 || n > kMaxPageSize)
      return badParameter("page_size", quotedValue(it->second) + " is not an integer from 1 to 1000", target);
    filter.limit = n;
  }
  if (auto it = target.query.find("page_token"); it != target.query.end()) {
    // The token carries the filters it was issued for, so a page never mixes two listings.
    // Signed (PageToken.hpp): a token the server did not issue is refused, however well formed.
    const auto verified = verifyPageToken(it->second, config_.pageTokenKey);
    const nlohmann::json token = verified ? *verified : nlohmann::json();
    // The owner filter is in it too: a token issued to one user is refused to another.
    if (!token.is_object() || !token.contains("after") || !token["after"].is_number_integer() ||
        token.value("state", "") != filter.state || token.value("kind", "") != filter.kind ||
        token.value("owner", "") != filter.owner)
      return badParameter("page_token",
                          "not a token from a previous page of this listing (same filters)", target);
    filter.afterSeq = token["after"].get<std::int64_t>();
  }
  // Fetch one more than asked: whether it exists decides if there is a next page.
  const int pageSize = filter.limit;
  filter.limit = pageSize + 1;
  auto rows = othersOnly ? std::vector<JobRecord>() : store_.listJobs(filter);
  nlohmann::json body = {{"jobs", nlohmann::json::array()}};
  const bool more = static_cast<int>(rows.size()) > pageSize;
  if (more) rows.resize(static_cast<std::size_t>(pageSize));
  for (const auto& job : rows) body["jobs"].push_back(toJson(job));
  if (more) {
    nlohmann::json token = {{"after", rows.back().seq}, {"state", filter.state}, {"kind", filter.kind}};
    // Only when set: an admin's unfiltered listing has tokens without an owner, as a single-token server's.
    if (!filter.owner.empty()) token["owner"] = filter.owner;
    body["next_page_token"] = signPageToken(token, config_.pageTokenKey);
  }
  return jsonResponse(http::status::ok, body);
}

Response JobsApi::get(const std::string& id, const Target& target, const Caller& caller) {
  const auto view = target.query.find("view");
  if (view != target.query.end() && view->second != "full" && view->second != "basic")
    return badParameter("view", quotedValue(view->second) + " is not one of basic, full", target);
  const bool full = view != target.query.end() && view->second == "full";
  if (!full)
    if (const auto cached = views_.find(id)) {
      if (!caller.mayAccess(cached->owner)) return notFound(id, target);
      return textResponse(http::status::ok, cached->body, "application/json");
    }
  const auto generation = views_.generation();  // before the read: a write after it voids the body
  const auto job = store_.job(id);
  if (!job || !caller.mayAccess(job->owner)) return notFound(id, target);
  if (full) return jsonResponse(http::status::ok, toJson(*job, true));
  auto rendered = std::make_shared<const JobViewCache::View>(JobViewCache::View{job->owner, jsonText(toJson(*job))});
  views_.store(id, rendered, generation);
  return textResponse(http::status::ok, rendered->body, "application/json");
}

Response JobsApi::events(const std::string& id, const Target& target, const Caller& caller) {
  if (!visibleJob(id, caller)) return notFound(id, target);
  nlohmann::json out = nlohmann::json::array();
  for (const auto& e : store_.events(id))
    out.push_back({{"at", e.at},
                   {"from", e.from.empty() ? nlohmann::json() : nlohmann::json(e.from)},
                   {"to", e.to},
                   {"reason", e.reason}});
  return jsonResponse(http::status::ok, {{"events", out}});
}

Response JobsApi::cancel(const std::string& id, const Target& target, const Caller& caller) {
  // Compare-and-set loop: the worker pool may move the job between our read and our write.
  for (int attempt = 0; attempt < 5; ++attempt) {
    const auto job = visibleJob(id, caller);
    if (!job) return notFound(id, target);
    if (state::isFinal(job->state))
      return problem(http::status::conflict, "job-finished", "Job already finished",
                     "job " + id + " is " + job->state + " and cannot be cancelled", target.path);
    if (job->state == state::cancelling) return jsonResponse(http::status::accepted, toJson(*job));
    if (job->state == state::queued &&
        store_.transition(id, state::queued, state::cancelled, "cancelled by " + caller.name))
      return jsonResponse(http::status::ok, toJson(*store_.job(id)));
    if (job->state == state::running &&
        store_.transition(id, state::running, state::cancelling, "cancel requested by " + caller.name)) {
      pool_.terminate(id);
      return jsonResponse(http::status::accepted, toJson(*store_.job(id)));
    }
  }
  return problem(http::status::conflict, "job-busy", "Job changed state repeatedly",
                 "try the cancel again", target.path);
}

Response JobsApi::retry(const std::string& id, const Target& target, const Caller& caller) {
  const auto job = visibleJob(id, caller);
  if (!job) return notFound(id, target);
  if (job->state != state::failed && job->state != state::cancelled)
    return problem(http::status::conflict, "job-not-retryable", "Job cannot be retried",
                   "job " + id + " is " + job->state + "; only a FAILED or CANCELLED job is retried", target.path);
  std::error_code ec;
  const bool checkpoint = std::filesystem::exists(config_.jobDir(id) / "checkpoint.h5", ec);
  if (!store_.transition(id, job->state, state::queued,
                         "retry requested by " + caller.name +
                             (checkpoint ? "; resumes from its checkpoint"
                                         : "; no checkpoint, starts from the beginning")))
    return problem(http::status::conflict, "job-busy", "Job changed state", "try the retry again", target.path);
  pool_.wake();
  return jsonResponse(http::status::ok, toJson(*store_.job(id)));
}

Response JobsApi::result(const std::string& id, const Target& target, const Caller& caller) {
  const auto job = visibleJob(id, caller);
  if (!job) return notFound(id, target);
  if (job->state != state::succeeded) return notFinished(*job, target, "a result");
  const auto summary = store_.summary(id);
  if (!summary)
    return problem(http::status::internal_server_error, "summary-missing", "Summary missing",
                   "job " + id + " succeeded but its summary is not stored", target.path);
  return jsonResponse(http::status::ok, *summary);
}

Response JobsApi::coverage(const std::string& id, const Target& target, const Caller& caller) {
  const auto job = visibleJob(id, caller);
  if (!job) return notFound(id, target);
  if (job->state != state::succeeded) return notFinished(*job, target, "a coverage distribution");
  std::string format = "json";
  if (auto it = target.query.find("format"); it != target.query.end()) format = it->second;
  if (format != "json" && format != "csv" && format != "h5")
    return badParameter("format", quotedValue(format) + " is not one of json, csv, h5", target);
  const auto stored = store_.coverage(id);
  if (stored.empty())
    return problem(http::status::not_found, "no-coverage", "No coverage distribution",
                   "job " + id + " (" + job->kind + ") has no coverage histogram; spray jobs have one",
                   target.path);
  std::vector<CoverageBin> bins = stored;
  if (auto it = target.query.find("bins"); it != target.query.end()) {
    std::size_t n = 0;
    try {
      std::size_t used = 0;
      n = std::stoul(it->second, &used);
      if (used != it->second.size()) n = 0;
    } catch (...) {
      n = 0;
    }
    if (n == 0 || stored.size() % n != 0)
      return badParameter("bins",
                          "must divide the stored " + std::to_string(stored.size()) +
                              " bins (adjacent bins are merged); allowed: " +
                              divisorsText(stored.size()),
                          target);
    bins = mergeBins(stored, n);
  }
  // An ensemble's band over its members, from the member counts in its summary.
  std::optional<CoverageBand> band;
  if (const auto summary = store_.summary(id)) band = coverageBand(*summary, bins.size());
  const CoverageBand* withBand = band ? &*band : nullptr;
  if (format == "json") return jsonResponse(http::status::ok, coverageJson(id, bins, withBand));
  if (format == "csv") {
    auto res = textResponse(http::status::ok, coverageCsv(bins, withBand), "text/csv; charset=utf-8");
    res.set(http::field::content_disposition, "attachment; filename=\"coverage.csv\"");
    return res;
  }
  const std::string exportName = "coverage_" + std::to_string(bins.size()) + ".h5.export";
  // HDF5 would write through a symlink left at that name (or at the job's folder): the folder must be
  // a real one, and a fresh file is made in it.
  {
    const Descriptor folder(openJobFolder(config_, id));
    if (folder.get() < 0)
      return problem(http::status::internal_server_error, "export-failed", "Export failed",
                     "the folder of job " + id + " is missing or not a directory", target.path);
    (void)::unlinkat(folder.get(), exportName.c_str(), 0);
  }
  const auto path = config_.jobDir(id) / exportName;
  std::string error;
  if (!writeCoverageH5(path, id, bins, error, withBand))
    return problem(http::status::internal_server_error, "export-failed", "Export failed", error,
                   target.path);
  const int fd = openJobFile(config_, id, exportName);
  if (fd < 0)
    return problem(http::status::internal_server_error, "export-failed", "Export failed",
                   "the written export cannot be opened as a regular file", target.path);
  return fileResponse(fd, "application/x-hdf5", "coverage.h5");
}

Response JobsApi::artifact(const std::string& id, const std::string& name, const Target& target,
                           const Caller& caller) {
  if (!isArtifactName(name))
    return problem(http::status::bad_request, "invalid-artifact-name", "Invalid artifact name",
                   "\"" + name + "\" is not an artifact name: database.h5, result.h5, their ParaView "
                   "sidecars database.xmf and result.xmf, summary.json, solver.log, job.json or a figure "
                   "NAME.svg; paths are never accepted",
                   target.path);
  const auto job = visibleJob(id, caller);
  if (!job) return notFound(id, target);
  // A symlink is never followed, whether the name, the job's folder or jobs/ is one: only files the
  // job wrote into its folder are served, as "not found" otherwise.
  const int fd = openJobFile(config_, id, name);
  if (fd < 0)
    return problem(http::status::not_found, "artifact-not-found", "Artifact not found",
                   "job " + id + " (" + job->state + ") has no artifact \"" + name + "\"",
                   target.path);
  if (name == "job.json") return servedJobFile(fd, *job, target);
  return fileResponse(fd, contentTypeFor(name), name);
}

Response JobsApi::servedJobFile(int fd, const JobRecord& job, const Target& target) const {
  std::string text;
  {
    const Descriptor file(fd);
    char chunk[65536];
    ssize_t n;
    while ((n = ::read(file.get(), chunk, sizeof chunk)) != 0) {
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) break;
      text.append(chunk, static_cast<std::size_t>(n));
    }
    if (n < 0)
      return problem(http::status::internal_server_error, "artifact-unreadable", "Artifact unreadable",
                     "job.json of job " + job.id + " cannot be read", target.path);
  }
  auto document = nlohmann::json::parse(text, nullptr, false);
  if (document.is_discarded())
    return problem(http::status::internal_server_error, "artifact-unreadable", "Artifact unreadable",
                   "job.json of job " + job.id + " is not JSON", target.path);
  // The worker gives the solver the database as a path on this machine; the client sees the id it
  // gave, and any other path inside the data directory relative to it.
  if (!job.databaseRef.empty() && document.is_object()) document["database"] = job.databaseRef;
  relativeToDataDir(document, (config_.dataDir / "").string());
  const std::string served = document.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  auto res = textResponse(http::status::ok, served, contentTypeFor("job.json"));
  res.set(http::field::content_disposition, "attachment; filename=\"job.json\"");
  return res;
}

}  // namespace rcfd::server
