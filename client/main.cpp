// rcfd: the command-line client of rcfd-server (docs/api.md). Exit codes: 0 success, 1 the server or
// the job failed (or cannot be reached), 2 usage error or input the server rejected as invalid.

#include <algorithm>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <optional>
#include <thread>

#include "HttpClient.hpp"
#include "ProgressView.hpp"

using namespace rcfd::client;
using nlohmann::json;

namespace {

constexpr int kOk = 0, kFailed = 1, kInvalid = 2;

/// A failure already explained to the user; carries the exit code.
struct Exit {
  int code;
};

std::string envOr(const char* name, const std::string& fallback) {
  const char* v = std::getenv(name);
  return v && *v ? std::string(v) : fallback;
}

/// Prints an HTTP error: the problem's title, detail and pointers when the body is problem+json.
[[noreturn]] void fail(const HttpResponse& res, const std::string& what) {
  std::cerr << "error: " << what << ": HTTP " << res.status;
  const auto body = json::parse(res.body, nullptr, false);
  if (body.is_object() && body.contains("title")) {
    std::cerr << " " << body.value("title", "") << "\n";
    if (body.contains("detail") && body["detail"].is_string())
      std::cerr << "  " << body["detail"].get<std::string>() << "\n";
    if (body.contains("errors") && body["errors"].is_array())
      for (const auto& e : body["errors"]) {
        const std::string pointer = e.value("pointer", "");
        std::cerr << "  " << (pointer.empty() ? "(whole document)" : pointer) << ": "
                  << e.value("message", "") << "\n";
      }
  } else {
    std::cerr << "\n" << (res.body.size() > 500 ? res.body.substr(0, 500) + "..." : res.body) << "\n";
  }
  if (res.status == 401)
    std::cerr << "  (give the server's token with --token or RCFD_TOKEN)\n";
  const bool invalid = res.status == 400 || res.status == 413 || res.status == 415 || res.status == 422;
  throw Exit{invalid ? kInvalid : kFailed};
}

json parseJson(const HttpResponse& res) {
  auto j = json::parse(res.body, nullptr, false);
  if (j.is_discarded()) {
    std::cerr << "error: the server answered with invalid JSON\n";
    throw Exit{kFailed};
  }
  return j;
}

/// Reads a job file; a "scene_file" is read (relative to the job file) and inlined as "scene".
json readJobFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    std::cerr << "error: cannot read job file " << path << "\n";
    throw Exit{kInvalid};
  }
  auto job = json::parse(in, nullptr, false);
  if (job.is_discarded() || !job.is_object()) {
    std::cerr << "error: " << path << " is not a JSON object\n";
    throw Exit{kInvalid};
  }
  if (job.contains("scene_file")) {
    if (!job["scene_file"].is_string()) {
      std::cerr << "error: " << path << ": /scene_file must be a string (a path)\n";
      throw Exit{kInvalid};
    }
    const auto scenePath =
        std::filesystem::path(path).parent_path() / job["scene_file"].get<std::string>();
    std::ifstream sceneIn(scenePath);
    auto scene = json::parse(sceneIn, nullptr, false);
    if (!sceneIn || scene.is_discarded()) {
      std::cerr << "error: " << path << ": /scene_file: cannot read JSON from " << scenePath.string()
                << "\n";
      throw Exit{kInvalid};
    }
    job.erase("scene_file");
    job["scene"] = scene;
  }
  return job;
}

std::string fmtNumber(const json& j) {
  if (!j.is_number()) return "-";
  char out[32];
  std::snprintf(out, sizeof out, "%.6g", j.get<double>());
  return out;
}

void printStatus(const json& job) {
  std::cout << "id:        " << job.value("id", "") << "\n"
            << "kind:      " << job.value("kind", "") << "\n"
            << "state:     " << job.value("state", "") << "\n";
  const auto& p = job["progress"];
  std::cout << "progress:  " << fmtNumber(p["fraction"].is_number() ? json(100 * p["fraction"].get<double>()) : json()) << " %"
            << "  sim_time " << fmtNumber(p["sim_time"]) << " s  eta " << fmtNumber(p["eta_s"]) << " s\n";
  if (p.contains("phase") && p["phase"].is_string()) {
    std::cout << "phase:     " << p["phase"].get<std::string>();
    if (p.contains("phase_fraction") && p["phase_fraction"].is_number())
      std::cout << " " << fmtNumber(json(100 * p["phase_fraction"].get<double>())) << " %";
    std::cout << "\n";
  }
  for (const char* key : {"owner", "database", "created_at", "started_at", "finished_at", "error"})
    if (job.contains(key) && job[key].is_string())
      std::cout << key << ":" << std::string(std::max<std::size_t>(1, 10 - std::min<std::size_t>(10, std::string(key).size())), ' ')
                << job[key].get<std::string>() << "\n";
  if (job.contains("artifacts") && !job["artifacts"].empty()) {
    std::cout << "artifacts:";
    for (const auto& a : job["artifacts"]) std::cout << " " << a.get<std::string>();
    std::cout << "\n";
  }
}

/// The job's status; while the server cannot be reached or answers that it is unavailable (502, 503,
/// 504: restarting, or behind a proxy whose backend is), retried with growing pauses for up to
/// `reconnectSeconds` from the first failure, saying so once on stderr.
HttpResponse statusAcrossRestarts(HttpClient& client, const std::string& id, double reconnectSeconds) {
  using Clock = std::chrono::steady_clock;
  std::optional<Clock::time_point> firstFailure;
  double pause = 0.25;
  for (;;) {
    std::string problem;
    try {
      auto res = client.get("/v1/jobs/" + id);
      if (res.status != 502 && res.status != 503 && res.status != 504) {
        if (firstFailure) std::cerr << "server " << client.server() << " answers again\n";
        return res;
      }
      problem = "answered " + std::to_string(res.status);
    } catch (const ConnectionError& e) {
      problem = e.what();
    }
    const auto now = Clock::now();
    if (!firstFailure) {
      firstFailure = now;
      std::cerr << "server " << client.server() << " unreachable (" << problem << "); retrying for up to "
                << reconnectSeconds << " s\n";
    }
    if (std::chrono::duration<double>(now - *firstFailure).count() >= reconnectSeconds)
      throw ConnectionError(problem + " (gave up after " + std::to_string(int(reconnectSeconds)) +
                            " s of retries; the job may still be running: rcfd wait " + id + ")");
    std::this_thread::sleep_for(std::chrono::duration<double>(pause));
    pause = std::min(2.0 * pause, 5.0);
  }
}

/// Polls until the job is final; 0 if it SUCCEEDED.
int waitFor(HttpClient& client, const std::string& id, double intervalSeconds, double reconnectSeconds) {
  ProgressView view(::isatty(STDERR_FILENO) != 0);  // progress on stderr: stdout stays the job id
  for (;;) {
    auto res = statusAcrossRestarts(client, id, reconnectSeconds);
    if (!res.ok()) fail(res, "status of job " + id);
    const auto job = parseJson(res);
    view.update(job);
    const std::string state = job.value("state", "");
    if (state == "SUCCEEDED" || state == "FAILED" || state == "CANCELLED") {
      view.finish();
      if (state == "SUCCEEDED") return kOk;
      std::cerr << "job " << id << " " << state;
      if (job.contains("error") && job["error"].is_string())
        std::cerr << ": " << job["error"].get<std::string>();
      std::cerr << "\n";
      return kFailed;
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(intervalSeconds));
  }
}

std::string urlEncode(const std::string& s) {
  std::string out;
  char hex[4];
  for (unsigned char c : s) {
    if (std::isalnum(c) || c == '-' || c == '_' || c == '.' || c == '~') out.push_back(static_cast<char>(c));
    else {
      std::snprintf(hex, sizeof hex, "%%%02X", c);
      out += hex;
    }
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rcfd: client of the rcfd job server (docs/api.md)"};
  std::string server = envOr("RCFD_SERVER", "http://127.0.0.1:8080");
  std::string token = envOr("RCFD_TOKEN", "");
  app.add_option("--server", server, "server URL (env RCFD_SERVER)")->capture_default_str();
  app.add_option("--token", token, "bearer token (env RCFD_TOKEN)");
  std::string caFile = envOr("RCFD_CACERT", "");
  app.add_option("--cacert", caFile,
                 "PEM file of the CA certificates an https:// server's certificate is checked against "
                 "(env RCFD_CACERT; default: the system's)");
  int timeoutSeconds = std::atoi(envOr("RCFD_TIMEOUT", "60").c_str());
  app.add_option("--timeout", timeoutSeconds, "seconds to wait for the server to connect or answer (env RCFD_TIMEOUT)")
      ->capture_default_str()->check(CLI::Range(1, 86400));
  app.require_subcommand(1);

  std::string file, id, name, output, state, kind, owner, key, format = "csv";
  bool wait = false, asJson = false;
  int bins = 0;
  double interval = 1.0, reconnect = 600.0;

  auto* submit = app.add_subcommand("submit", "submit a job file (scene_file is inlined)");
  submit->add_option("JOB", file, "job file (docs/contracts.md)")->required();
  submit->add_flag("--wait", wait, "wait for the job and show its progress");
  submit->add_option("--idempotency-key", key, "a retry with the same key returns the same job");
  auto* jobs = app.add_subcommand("jobs", "list jobs");
  jobs->add_option("--state", state, "QUEUED, RUNNING, SUCCEEDED, FAILED, CANCELLING or CANCELLED");
  jobs->add_option("--kind", kind, "database, calibration or spray");
  jobs->add_option("--owner", owner, "one user's jobs (admins; a user sees only their own anyway)");
  auto* status = app.add_subcommand("status", "show a job");
  status->add_option("ID", id)->required();
  status->add_flag("--json", asJson, "print the job resource as JSON");
  auto* waitCmd = app.add_subcommand("wait", "wait for a job, showing progress and ETA");
  waitCmd->add_option("ID", id)->required();
  for (auto* sub : {submit, waitCmd}) {
    sub->add_option("--interval", interval, "seconds between polls")->capture_default_str();
    sub->add_option("--reconnect", reconnect,
                    "seconds to keep retrying while the server is unreachable (a restart) before giving up")
        ->capture_default_str()->check(CLI::Range(0.0, 86400.0));
  }
  auto* cancel = app.add_subcommand("cancel", "cancel a job");
  cancel->add_option("ID", id)->required();
  auto* retry = app.add_subcommand("retry", "queue a failed or cancelled job again (resumes from its checkpoint)");
  retry->add_option("ID", id)->required();
  auto* result = app.add_subcommand("result", "print a succeeded job's summary.json");
  result->add_option("ID", id)->required();
  auto* coverage = app.add_subcommand("coverage", "download a spray job's coverage distribution");
  coverage->add_option("ID", id)->required();
  coverage->add_option("--format", format, "csv, json or h5")
      ->check(CLI::IsMember({"csv", "json", "h5"}))->capture_default_str();
  coverage->add_option("--bins", bins, "merge into N bins (N divides the stored bin count)");
  coverage->add_option("-o,--output", output, "output file")->required();
  auto* download = app.add_subcommand("download", "download an artifact of a job");
  download->add_option("ID", id)->required();
  download->add_option("NAME", name, "database.h5, result.h5, database.xmf, result.xmf, summary.json, solver.log or NAME.svg")
      ->required();
  download->add_option("-o,--output", output, "output file (default: NAME)");
  auto* health = app.add_subcommand("health", "check that the server answers (no token needed)");
  auto* upload = app.add_subcommand("upload", "upload a field database (HDF5, docs/formats.md)");
  upload->add_option("DB", file, "database file")->required()->check(CLI::ExistingFile);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? kOk : kInvalid;
  }

  try {
    HttpClient client(server, token, std::chrono::seconds(std::max(1, timeoutSeconds)), caFile);
    if (submit->parsed()) {
      const json body = readJobFile(file);
      std::map<std::string, std::string> headers;
      if (!key.empty()) headers["Idempotency-Key"] = key;
      auto res = client.post("/v1/jobs", body.dump(), headers);
      if (!res.ok()) fail(res, "submit " + file);
      const auto job = parseJson(res);
      const std::string jobId = job.value("id", "");
      std::cout << jobId << std::endl;
      std::cerr << "submitted " << job.value("kind", "") << " job " << jobId << " ("
                << job.value("state", "") << ")\n";
      return wait ? waitFor(client, jobId, interval, reconnect) : kOk;
    }
    if (jobs->parsed()) {
      std::string query = "?page_size=200";
      if (!state.empty()) query += "&state=" + urlEncode(state);
      if (!kind.empty()) query += "&kind=" + urlEncode(kind);
      if (!owner.empty()) query += "&owner=" + urlEncode(owner);
      std::printf("%-32s  %-11s  %-10s  %7s  %-12s  %s\n", "ID", "KIND", "STATE", "DONE", "OWNER", "CREATED");
      std::string pageToken;
      do {
        auto res = client.get("/v1/jobs" + query +
                              (pageToken.empty() ? "" : "&page_token=" + urlEncode(pageToken)));
        if (!res.ok()) fail(res, "list jobs");
        const auto page = parseJson(res);
        for (const auto& j : page["jobs"])
          std::printf("%-32s  %-11s  %-10s  %6.1f%%  %-12s  %s\n", j.value("id", "").c_str(),
                      j.value("kind", "").c_str(), j.value("state", "").c_str(),
                      100 * j["progress"].value("fraction", 0.0), j.value("owner", "").c_str(),
                      j.value("created_at", "").c_str());
        pageToken = page.value("next_page_token", "");
      } while (!pageToken.empty());
      return kOk;
    }
    if (status->parsed()) {
      auto res = client.get("/v1/jobs/" + urlEncode(id));
      if (!res.ok()) fail(res, "status of job " + id);
      const auto job = parseJson(res);
      if (asJson) std::cout << job.dump(2) << "\n";
      else printStatus(job);
      return kOk;
    }
    if (waitCmd->parsed()) return waitFor(client, urlEncode(id), interval, reconnect);
    if (cancel->parsed() || retry->parsed()) {
      const std::string action = cancel->parsed() ? "cancel" : "retry";
      auto res = client.post("/v1/jobs/" + urlEncode(id) + ":" + action, "");
      if (!res.ok()) fail(res, action + " job " + id);
      const auto job = parseJson(res);
      std::cout << job.value("id", "") << " " << job.value("state", "") << "\n";
      return kOk;
    }
    if (result->parsed()) {
      auto res = client.get("/v1/jobs/" + urlEncode(id) + "/result");
      if (!res.ok()) fail(res, "result of job " + id);
      std::cout << parseJson(res).dump(2) << "\n";
      return kOk;
    }
    if (coverage->parsed()) {
      std::string target = "/v1/jobs/" + urlEncode(id) + "/coverage?format=" + format;
      if (bins > 0) target += "&bins=" + std::to_string(bins);
      auto res = client.download(target, output);
      if (!res.ok()) fail(res, "coverage of job " + id);
      std::cerr << "wrote " << output << "\n";
      return kOk;
    }
    if (download->parsed()) {
      if (output.empty()) output = name;
      auto res = client.download("/v1/jobs/" + urlEncode(id) + "/artifacts/" + urlEncode(name), output);
      if (!res.ok()) fail(res, "download " + name + " of job " + id);
      std::cerr << "wrote " << output << "\n";
      return kOk;
    }
    if (health->parsed()) {
      auto res = client.get("/v1/health");
      if (!res.ok()) fail(res, "health");
      std::cout << parseJson(res).dump() << "\n";
      return kOk;
    }
    if (upload->parsed()) {
      auto res = client.postFile("/v1/databases", file);
      if (!res.ok()) fail(res, "upload " + file);
      const auto db = parseJson(res);
      std::cout << db.value("id", "") << std::endl;
      std::cerr << "uploaded " << file << ": database " << db.value("id", "") << " ("
                << db.value("frames", 0) << " frames); use it as \"database\" in a job file\n";
      return kOk;
    }
    return kInvalid;
  } catch (const Exit& e) {
    return e.code;
  } catch (const ConnectionError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kFailed;
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kInvalid;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kFailed;
  }
}
