// A fuzz test of rcfd-server's HTTP API on loopback: random methods, targets built from the real
// routes (server/Router.cpp) and mutated, headers (token or not, Content-Type, Idempotency-Key,
// Content-Length that lies, chunked bodies) and bodies (valid jobs, jobs mutated at random JSON
// pointers, truncated JSON, deep nesting, numbers beyond double range, random bytes, database
// uploads whole, cut short or with bytes changed), all from one seed, written as raw bytes so the
// framing can be wrong on purpose, one connection at a time (some carrying a few requests). Every
// answer must be below 500, and a problem+json with type, title, status and instance when it is an
// error; no answer may take over 10 s; the server must live through all of it, answer health after,
// list exactly the jobs it answered 2xx with a Location to, stop cleanly, and leave a database that
// passes PRAGMA integrity_check and foreign_key_check. Workers are 0 (jobs stay QUEUED); a second run
// aims at a spray job that one real solver run made SUCCEEDED, so result, coverage and artifacts are
// served too. The regression tests at the end are what the fuzzing found.
//
//   RCFD_FUZZ_SEED=<n> (default 35; "random" draws one) and RCFD_FUZZ_REQUESTS=<n> (default 5000;
//   the second run gets 30 % of it) replay or lengthen a run:
//   RCFD_FUZZ_SEED=7 RCFD_FUZZ_REQUESTS=50000 build/tests/rcfd-test-server --gtest_filter='ServerFuzz.*'
// A failure prints the seed, the count and the requests of the connection that failed.

#include <gtest/gtest.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sqlite3.h>
#include <sys/socket.h>

#include <algorithm>
#include <cstdlib>
#include <set>
#include <sstream>

#include "ServerFixture.hpp"
#include "SmallDatabase.hpp"
#include "scene/SchemaValidator.hpp"

using namespace rcfd::test;
namespace http = boost::beast::http;

namespace {

constexpr const char* kToken = "fuzz-token-5f0c";
constexpr std::uint64_t kDefaultSeed = 35;
constexpr long kDefaultRequests = 5000;
constexpr std::size_t kJsonBodyLimit = 1u << 20;  // the server's default --max-body-bytes
constexpr auto kAnswerTimeout = std::chrono::seconds(10);  // longer than this is a hang
constexpr const char* kUploadCheckSeconds = "4";           // the servers' --upload-check-timeout

/// The seed and the request count of this run, from RCFD_FUZZ_SEED and RCFD_FUZZ_REQUESTS.
struct FuzzSettings {
  std::uint64_t seed = kDefaultSeed;
  long requests = kDefaultRequests;  ///< of the main fuzz test; the others scale with it

  static FuzzSettings fromEnvironment() {
    FuzzSettings s;
    if (const char* text = std::getenv("RCFD_FUZZ_SEED"); text && *text) {
      if (std::string(text) == "random") s.seed = (std::uint64_t(std::random_device{}()) << 32) | std::random_device{}();
      else s.seed = std::stoull(text);
    }
    if (const char* text = std::getenv("RCFD_FUZZ_REQUESTS"); text && *text) s.requests = std::max(1L, std::stol(text));
    return s;
  }
  /// A count that is `defaultCount` in the default run and grows with RCFD_FUZZ_REQUESTS.
  long scaled(long defaultCount) const { return std::max(1L, requests * defaultCount / kDefaultRequests); }
  std::string replay(const std::string& test) const {
    return "replay: RCFD_FUZZ_SEED=" + std::to_string(seed) + " RCFD_FUZZ_REQUESTS=" + std::to_string(requests) +
           " build/tests/rcfd-test-server --gtest_filter='" + test + "'";
  }
};

/// Bytes shown in a failure message: printable ASCII as is, the rest as \xNN, cut at `max`.
std::string printable(std::string_view bytes, std::size_t max = 1500) {
  std::string out;
  for (const char c : bytes.substr(0, max)) {
    const auto b = static_cast<unsigned char>(c);
    if (c == '\r') out += "\\r";
    else if (c == '\n') out += "\\n\n";
    else if (b >= 0x20 && b < 0x7f) out.push_back(c);
    else {
      static const char* const hex = "0123456789abcdef";
      out += {'\\', 'x', hex[b >> 4], hex[b & 15]};
    }
  }
  if (bytes.size() > max) out += "... (" + std::to_string(bytes.size()) + " bytes)";
  return out;
}

// ---------------------------------------------------------------------------------------------
// Requests as bytes.

/// What a request's framing does: exact ones can be matched to their answers one to one.
enum class Framing { exact, noLength, shortLength, longLength, chunked, badChunked, badLength, overLimit };

struct FuzzRequest {
  std::string method = "GET";
  std::string target = "/";
  std::string version = "HTTP/1.1";
  std::vector<std::pair<std::string, std::string>> headers;
  std::string body;
  Framing framing = Framing::exact;
  bool unauthorized = false;  ///< certainly without the token (no Authorization header, or one wrong one)
  bool submitRoute = false;   ///< POST to what the server parses as /v1/jobs
  std::string wire;           ///< the bytes sent

  bool head() const { return method == "HEAD"; }
};

/// The path segments as the server splits them (empty ones dropped), without the query.
std::vector<std::string> segmentsOf(const std::string& target) {
  std::vector<std::string> out;
  const std::string path = target.substr(0, target.find('?'));
  std::size_t start = 1;
  while (start <= path.size()) {
    const auto end = std::min(path.find('/', start), path.size());
    if (end > start) out.push_back(path.substr(start, end - start));
    start = end + 1;
  }
  return out;
}

std::string chunkedEncoding(std::mt19937_64& rng, const std::string& body) {
  std::string out;
  std::size_t at = 0;
  while (at < body.size()) {
    const std::size_t n = std::min<std::size_t>(body.size() - at, 1 + rng() % 4096);
    char size[32];
    std::snprintf(size, sizeof size, "%zx", n);
    out += size;
    if (rng() % 8 == 0) out += ";ext=1";
    out += "\r\n" + body.substr(at, n) + "\r\n";
    at += n;
  }
  return out + "0\r\n\r\n";
}

// ---------------------------------------------------------------------------------------------
// The generator: all choices come from one std::mt19937_64. What it knows of the server (job and
// database ids, page tokens it was given) comes from earlier answers, so a replay with the same seed
// makes the same choices as long as the server answers the same way.

struct Known {
  std::vector<std::string> jobs;       ///< ids of accepted jobs (all kinds)
  std::vector<std::string> databaseJobs;
  std::vector<std::string> databases;  ///< ids of uploaded databases
  std::vector<std::string> pageTokens;
  std::string finishedJob;             ///< a SUCCEEDED spray job, if the test made one: aimed at
  std::vector<std::string> artifacts;  ///< its artifacts
};

class RequestGenerator {
 public:
  RequestGenerator(std::uint64_t seed, std::string token, nlohmann::json scene, std::string database)
      : rng_(seed), token_(std::move(token)), scene_(std::move(scene)), database_(std::move(database)) {
    filePaths_ = rcfd::SchemaValidator::get("scene").filePathPointers();
  }

  /// The requests of one connection (one, or a few pipelined).
  std::vector<FuzzRequest> connection(const Known& known) {
    const std::size_t n = chance(0.8) ? 1 : 2 + below(3);
    std::vector<FuzzRequest> out;
    for (std::size_t i = 0; i < n; ++i) out.push_back(request(known));
    return out;
  }

  FuzzRequest request(const Known& known) {
    FuzzRequest r;
    const Route route = pickRoute(!known.finishedJob.empty());
    r.method = methodFor(route);
    r.target = targetFor(route, known);
    if (chance(0.15)) r.target = mutateTarget(r.target, known);
    if (chance(0.35)) r.target += "?" + query(known);
    if (chance(0.03)) r.version = pick<std::string>({"HTTP/1.0", "HTTP/1.0", "HTTP/2.0", "HTTP/1.2", "HTTP/9.9", "HTTP/1", "FOO/1.1", "http/1.1"});
    const bool originForm = !r.target.empty() && r.target.front() == '/';
    const auto segments = segmentsOf(r.target);
    r.submitRoute = r.method == "POST" && originForm && segments == std::vector<std::string>{"v1", "jobs"};
    const bool upload = r.method == "POST" && originForm && segments == std::vector<std::string>{"v1", "databases"};
    if (!chance(0.03)) r.headers.emplace_back("Host", "127.0.0.1");
    authorization(r);
    std::string contentType;
    if (r.submitRoute || upload || chance(0.1)) {
      r.body = r.submitRoute ? jobBody(known) : upload ? uploadBody() : otherBody();
      contentType = upload ? pick<std::string>({"application/octet-stream", "application/x-hdf5", ""}) : "application/json";
    }
    if (chance(0.12)) contentType = pick<std::string>(
        {"", "application/json; charset=utf-8", "APPLICATION/JSON", "application/json ;", "application/json;;;",
         "text/plain", "application/x-www-form-urlencoded", "multipart/form-data; boundary=x",
         "application/problem+json", "application/jsonx", "application", "*/*", std::string(300, 'j'),
         "application/json\xff", " application/json"});
    if (!contentType.empty() || chance(0.05)) r.headers.emplace_back("Content-Type", contentType);
    if (r.submitRoute && chance(0.3)) r.headers.emplace_back("Idempotency-Key", idempotencyKey());
    else if (chance(0.02)) r.headers.emplace_back("Idempotency-Key", idempotencyKey());
    extraHeaders(r);
    frame(r);
    return r;
  }

 private:
  enum class Route { jobs, job, cancel, events, result, coverage, artifact, databases, database, health,
                     healthSlash, schema, metrics, root, v1, unknown };

  // Not std::uniform_real_distribution: its algorithm is the library's, and a seed must mean the same
  // requests everywhere.
  bool chance(double p) { return double(rng_() >> 11) * 0x1.0p-53 < p; }
  std::size_t below(std::size_t n) { return n == 0 ? 0 : std::size_t(rng_() % n); }
  template <class T>
  T pick(std::initializer_list<T> options) { return *(options.begin() + below(options.size())); }
  template <class T>
  const T& pickFrom(const std::vector<T>& options) { return options[below(options.size())]; }

  Route pickRoute(bool finishedJob) {
    // Weights: submits and job reads most, everything else still often; with a finished job to aim
    // at, its result, coverage and artifacts most.
    const int reads = finishedJob ? 4 : 1;
    const std::vector<std::pair<Route, int>> weights = {
        {Route::jobs, 30}, {Route::job, 10}, {Route::cancel, 8}, {Route::events, 5}, {Route::result, 5 * reads},
        {Route::coverage, 5 * reads}, {Route::artifact, 6 * reads}, {Route::databases, 5}, {Route::database, 4},
        {Route::health, 5}, {Route::healthSlash, 2}, {Route::schema, 4}, {Route::metrics, 3},
        {Route::root, 2}, {Route::v1, 1}, {Route::unknown, 5}};
    int total = 0;
    for (const auto& w : weights) total += w.second;
    int x = int(below(std::size_t(total)));
    for (const auto& [route, w] : weights) {
      if (x < w) return route;
      x -= w;
    }
    return Route::unknown;
  }

  std::string methodFor(Route route) {
    if (chance(0.25)) {
      return pick<std::string>({"GET", "POST", "PUT", "DELETE", "PATCH", "HEAD", "OPTIONS", "TRACE", "CONNECT",
                                "get", "Post", "PROPFIND", "M-SEARCH", "BREW", "X", std::string(64, 'G'),
                                "GE\x01T", "G\xc3\xa9T", "", "GET GET"});
    }
    switch (route) {
      case Route::jobs: return chance(0.75) ? "POST" : "GET";
      case Route::cancel: return "POST";
      case Route::databases: return "POST";
      default: return "GET";
    }
  }

  std::string id(const Known& known) {
    const std::size_t c = below(100);
    if (c < 40 && !known.finishedJob.empty()) return known.finishedJob;
    if (c < 60 && !known.jobs.empty()) return pickFrom(known.jobs);
    if (c < 65 && !known.databases.empty()) return pickFrom(known.databases);
    if (c < 80) {
      std::string s;
      for (int i = 0; i < 32; ++i) s.push_back("0123456789abcdef"[below(16)]);
      return s;
    }
    return pick<std::string>({"", "0", "x", "ABCDEF0123456789ABCDEF0123456789", std::string(33, 'a'),
                              std::string(31, 'f'), std::string(300, '9'), "%00", "%2e%2e", "..", ".",
                              "id with space", "\xff\xfe", "\xc3\x28", "'; DROP TABLE jobs; --", "%27%3B",
                              ":cancel", "a:cancel:cancel", "*", "null", "-1"});
  }

  std::string artifactName(const Known& known) {
    if (!known.artifacts.empty() && chance(0.5)) return pickFrom(known.artifacts);
    return pick<std::string>({"database.h5", "result.h5", "summary.json", "solver.log", "job.json", "coverage.svg",
                              "a.b.svg", "figure-1_x.svg", ".svg", "..svg", "x..svg", "../rcfd.sqlite",
                              "%2e%2e%2frcfd.sqlite", "rcfd.sqlite", "token", std::string(125, 'n') + ".svg",
                              std::string(130, 'n') + ".svg", "checkpoint.h5", "job.json.tmp", "JOB.JSON",
                              "coverage_4.h5.export", "x.svg\xff", ""});
  }

  std::string targetFor(Route route, const Known& known) {
    switch (route) {
      case Route::jobs: return "/v1/jobs";
      case Route::job: return "/v1/jobs/" + id(known);
      case Route::cancel: return "/v1/jobs/" + id(known) + ":cancel";
      case Route::events: return "/v1/jobs/" + id(known) + "/events";
      case Route::result: return "/v1/jobs/" + id(known) + "/result";
      case Route::coverage: return "/v1/jobs/" + id(known) + "/coverage";
      case Route::artifact: return "/v1/jobs/" + id(known) + "/artifacts/" + artifactName(known);
      case Route::databases: return "/v1/databases";
      case Route::database: return "/v1/databases/" + id(known);
      case Route::health: return "/v1/health";
      case Route::healthSlash: return "/v1/health/";
      case Route::schema:
        if (chance(0.2)) return pick<std::string>({"/v1/openapi.json", "/v1/openapi.json/x", "/v1/openapi"});
        return "/v1/schemas/" + pick<std::string>({"scene", "job", "job.schema.json", "nope", "", "../job", "%73cene"});
      case Route::metrics: return "/metrics";
      case Route::root: return "/";
      case Route::v1: return "/v1";
      case Route::unknown:
        return pick<std::string>({"/v2/jobs", "/v1/job", "/v1/jobs/x/y/z/w", "/V1/JOBS", "/favicon.ico",
                                  "/v1/databases/a/b", "/v1/health/x", "/metrics/", "//", "/v1//jobs//",
                                  "/v1/schemas", "/v1/schemas/scene/x", "/.git/config", "/v1/jobs/:cancel",
                                  "/web/app.js", "/web/", "/web/app.js/x", "/web/nope.css", "/v1/examples/quick",
                                  "/v1/examples/../job"});
    }
    return "/";
  }

  std::string percentEncoded(unsigned char c) {
    static const char* const hex = "0123456789ABCDEF";
    return {'%', hex[c >> 4], hex[c & 15]};
  }

  std::string mutateTarget(std::string t, const Known& known) {
    const int mutations = 1 + int(below(3));
    for (int m = 0; m < mutations; ++m) {
      const std::size_t at = t.empty() ? 0 : below(t.size() + 1);
      switch (below(14)) {
        case 0:  // percent-encode one character
          if (!t.empty() && at < t.size()) t.replace(at, 1, percentEncoded(static_cast<unsigned char>(t[at])));
          break;
        case 1: t.insert(at, pick<std::string>({"%", "%g1", "%4", "%zz", "%%", "%00", "%2F", "%2f", "%5C", "%FF"})); break;
        case 2: {  // a dot segment after some slash
          const auto slash = t.rfind('/', at);
          t.insert(slash == std::string::npos ? 0 : slash + 1,
                   pick<std::string>({"./", "../", "%2e/", "%2E%2E/", ".%2e/", "...", "../../../../etc/"}));
          break;
        }
        case 3: t.insert(at, "/"); break;
        case 4: t += "/"; break;
        case 5: {  // an overlong segment; a few are over the 16 KiB header limit
          const std::size_t n = pick<std::size_t>({200, 1000, 4096, 8000, 17000});
          t.insert(at, std::string(n, char('a' + below(26))));
          break;
        }
        case 6: {  // bytes that are not UTF-8
          std::string bytes;
          for (std::size_t i = 0, n = 1 + below(4); i < n; ++i) bytes.push_back(char(0x80 + below(0x80)));
          t.insert(at, bytes);
          break;
        }
        case 7: t.insert(at, std::string(1, char(pick<int>({0x01, 0x09, 0x7f, 0x00, 0x0b, '"', '<', '\\', '{', '#'})))); break;
        case 8: std::transform(t.begin(), t.end(), t.begin(), [](unsigned char c) { return char(std::toupper(c)); }); break;
        case 9: if (!t.empty()) t.erase(0, 1); break;  // no leading slash
        case 10: t = pick<std::string>({"http://127.0.0.1", "http://evil.example", "https://x:1"}) + t; break;
        case 11: t = pick<std::string>({"*", "", "?", "#", "/?", "/#x"}); break;
        case 12: t += pick<std::string>({":cancel", ":CANCEL", ":cancel:cancel", ":", "::cancel", ";cancel"}); break;
        case 13: {  // a real id somewhere
          const auto slash = t.rfind('/');
          t = t.substr(0, slash == std::string::npos ? 0 : slash + 1) + id(known);
          break;
        }
      }
    }
    return t;
  }

  std::string queryValue(const std::string& key, const Known& known) {
    if (key == "state") return pick<std::string>({"QUEUED", "RUNNING", "SUCCEEDED", "FAILED", "CANCELLING", "CANCELLED", "queued", "", "%FF%FE", "NOPE"});
    if (key == "kind") return pick<std::string>({"database", "spray", "calibration", "Spray", "", "%00"});
    if (key == "page_size") return pick<std::string>({"1", "2", "50", "1000", "1001", "0", "-1", "abc", "1e3", "2147483648", "99999999999999999999", " 1", "1 ", "+5", "0x10", ""});
    if (key == "page_token") {
      if (!known.pageTokens.empty() && chance(0.6)) {
        std::string token = pickFrom(known.pageTokens);
        if (chance(0.3) && !token.empty()) token[below(token.size())] = "A_-z9"[below(5)];
        return token;
      }
      return pick<std::string>({"", "forged", "eyJhZnRlciI6MX0", "eyJhZnRlciI6LTF9", "eyJhZnRlciI6MS41fQ",
                                "eyJhZnRlciI6OTIyMzM3MjAzNjg1NDc3NTgwOH0", "W10", "bnVsbA", "%FF", "===="});
    }
    if (key == "view") return pick<std::string>({"full", "basic", "FULL", "", "everything"});
    if (key == "format") return pick<std::string>({"json", "csv", "h5", "xml", "", "H5"});
    if (key == "bins") return pick<std::string>({"1", "2", "3", "4", "5", "10", "20", "0", "-2", "1000000", "18446744073709551616", "x", ""});
    return randomQueryText(1 + below(12));
  }

  std::string randomQueryText(std::size_t n) {
    static const std::string alphabet = "abcXYZ019-._~!$'()*,;:@/?+=&%";
    std::string s;
    for (std::size_t i = 0; i < n; ++i) {
      const auto c = below(10);
      if (c < 7) s.push_back(alphabet[below(alphabet.size())]);
      else if (c < 9) s += percentEncoded(static_cast<unsigned char>(below(256)));
      else s.push_back(char(0x80 + below(0x80)));
    }
    return s;
  }

  std::string query(const Known& known) {
    std::string q;
    const std::size_t n = below(5);
    for (std::size_t i = 0; i < n; ++i) {
      if (i) q += pick<std::string>({"&", "&", "&", "&&", ";"});
      const std::string key = chance(0.75) ? pick<std::string>({"state", "kind", "page_size", "page_token", "view", "format", "bins"})
                                           : randomQueryText(1 + below(8));
      q += key;
      if (!chance(0.1)) q += "=" + queryValue(key, known);
    }
    if (chance(0.02)) q += "&x=" + std::string(2000, 'v');
    return q;
  }

  void authorization(FuzzRequest& r) {
    const std::size_t c = below(100);
    if (c < 80) {
      // Whitespace around a field value is not part of it (RFC 9110 5.5): a trailing space is allowed.
      r.headers.emplace_back("Authorization", pick<std::string>({"Bearer ", "Bearer ", "Bearer ", "bearer ", "BEARER "}) + token_ +
                                                  (chance(0.05) ? " " : ""));
    } else if (c < 88) {
      r.unauthorized = true;  // no header at all
    } else if (c < 97) {
      r.unauthorized = true;
      r.headers.emplace_back("Authorization",
                             pick<std::string>({"Bearer", "Bearer ", "Bearer  " + token_, "Bearer " + token_ + " x",
                                                "Bearer " + token_.substr(0, token_.size() - 1),
                                                "Bearer " + token_ + "x", "Basic " + token_, token_,
                                                "Bearer " + std::string(token_.size(), 'a'),
                                                "Bearer \xff" + token_.substr(1), "Bearer " + std::string(4000, 't')}));
    } else {  // two headers: the server takes the first; not counted as certainly unauthorized
      r.headers.emplace_back("Authorization", chance(0.5) ? "Bearer wrong" : "Bearer " + token_);
      r.headers.emplace_back("Authorization", chance(0.5) ? "Bearer wrong" : "Bearer " + token_);
    }
  }

  std::string idempotencyKey() {
    const std::size_t c = below(10);
    if (c < 5) return "fuzz-key-" + std::to_string(below(6));  // reused: replays and conflicts
    if (c < 6) return "";
    if (c < 7) return std::string(200, 'k');
    if (c < 8) return std::string(201, 'k');
    if (c < 9) return std::string(1 + below(3000), 'q');
    std::string s;
    for (std::size_t i = 0, n = 1 + below(40); i < n; ++i) s.push_back(char(0x21 + below(0xdf)));
    return s;
  }

  void extraHeaders(FuzzRequest& r) {
    if (chance(0.05)) r.headers.emplace_back("Connection", pick<std::string>({"close", "keep-alive", "Upgrade", "close, keep-alive", "x"}));
    if (chance(0.02)) r.headers.emplace_back("Upgrade", "websocket");
    if (chance(0.02)) r.headers.emplace_back("Expect", "100-continue");
    if (chance(0.05)) r.headers.emplace_back("Accept", pick<std::string>({"*/*", "application/json", "text/html", ""}));
    if (chance(0.05)) r.headers.emplace_back("X-Fuzz-" + std::to_string(below(100)), randomQueryText(below(60)));
    if (chance(0.01)) r.headers.emplace_back("X-Padding", std::string(17000, 'p'));  // over the header limit
    if (chance(0.01)) r.headers.emplace_back("Bad Header", "x");
    if (chance(0.01)) r.headers.emplace_back("", "empty name");
    if (chance(0.01)) r.headers.emplace_back("X-Control", std::string("a\x01" "b"));
  }

  // --- bodies ---

  /// A JSON value of any type, small.
  nlohmann::json randomValue(int depth = 0) {
    switch (below(depth < 2 ? 13 : 10)) {
      case 0: return nullptr;
      case 1: return chance(0.5);
      case 2: return int(below(21)) - 10;
      case 3: return pick<std::int64_t>({0, -1, std::numeric_limits<std::int64_t>::max(), std::numeric_limits<std::int64_t>::min(), 1 << 30});
      case 4: return (chance(0.5) ? -1.0 : 1.0) * std::pow(10.0, double(int(below(600)) - 300));
      case 5: return pick<double>({0.0, -0.0, 0.5, 1e-9, 0.0123, 1e12, 5e-324, 1.7976931348623157e308});
      case 6: return randomQueryText(below(20));
      case 7: return pick<std::string>({"", "database", "spray", "/etc/passwd", "../../x", "\u00e9\u4e2d\U0001F600", std::string(1000, 's')});
      case 8: return raw(pick<std::string>({"1e400", "-1e400", "1e-400", "18446744073709551616", "9223372036854775808",
                                            "-9223372036854775809", "123456789012345678901234567890", "-0"}));
      case 9: return chance(0.5) ? nlohmann::json::array() : nlohmann::json::object();
      case 10: case 11: {
        nlohmann::json a = nlohmann::json::array();
        for (std::size_t i = 0, n = below(5); i < n; ++i) a.push_back(randomValue(depth + 1));
        return a;
      }
      default: {
        nlohmann::json o = nlohmann::json::object();
        for (std::size_t i = 0, n = below(4); i < n; ++i) o[randomQueryText(1 + below(6))] = randomValue(depth + 1);
        return o;
      }
    }
  }

  /// A marker string that stands for `token` in the document; dumping replaces it by the token's
  /// bytes verbatim (JSON could not hold them as they are).
  nlohmann::json raw(const std::string& token) {
    raws_.push_back(token);
    return "@@raw" + std::to_string(raws_.size() - 1) + "@@";
  }

  /// JSON text; strings that are not UTF-8 (random bytes) get U+FFFD (raw() places invalid ones).
  static std::string jsonText(const nlohmann::json& document, int indent = -1) {
    return document.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
  }

  std::string dumpWithRaws(const nlohmann::json& document) {
    std::string text = jsonText(document);
    for (std::size_t i = 0; i < raws_.size(); ++i) {
      const std::string marker = "\"@@raw" + std::to_string(i) + "@@\"";
      for (auto at = text.find(marker); at != std::string::npos; at = text.find(marker, at + raws_[i].size()))
        text.replace(at, marker.size(), raws_[i]);
    }
    raws_.clear();
    return text;
  }

  static void collectPointers(const nlohmann::json& node, const std::string& pointer, std::vector<std::string>& out) {
    if (!pointer.empty()) out.push_back(pointer);
    if (node.is_object()) {
      for (const auto& [key, value] : node.items()) {
        std::string token = key;
        for (std::size_t at = 0; (at = token.find('~', at)) != std::string::npos; at += 2) token.replace(at, 1, "~0");
        for (std::size_t at = 0; (at = token.find('/', at)) != std::string::npos; at += 2) token.replace(at, 1, "~1");
        collectPointers(value, pointer + "/" + token, out);
      }
    } else if (node.is_array()) {
      for (std::size_t i = 0; i < node.size(); ++i) collectPointers(node[i], pointer + "/" + std::to_string(i), out);
    }
  }

  /// One change at a random JSON pointer of `doc`.
  void mutate(nlohmann::json& doc) {
    std::vector<std::string> pointers;
    collectPointers(doc, "", pointers);
    if (pointers.empty()) return;
    const nlohmann::json::json_pointer at(pickFrom(pointers));
    nlohmann::json& node = doc[at];
    switch (below(8)) {
      case 0: case 1: node = randomValue(); break;
      case 2: {  // remove it
        const auto parent = at.parent_pointer();
        auto& container = doc[parent];
        if (container.is_object()) container.erase(at.back());
        else if (container.is_array() && !container.empty()) container.erase(container.begin() + std::ptrdiff_t(std::stoul(at.back())));
        break;
      }
      case 3: {  // an unknown sibling
        auto& container = doc[at.parent_pointer()];
        if (container.is_object()) container[randomQueryText(1 + below(8))] = randomValue();
        else if (container.is_array()) container.push_back(randomValue());
        break;
      }
      case 4:  // the same type, a strange value
        if (node.is_number()) node = node.get<double>() * pick<double>({0.0, -1.0, 1e-300, 1e300, 10.0, 1e6});
        else if (node.is_string()) node = node.get<std::string>() + pick<std::string>({"x", "", "\u00ff", std::string(500, 'z')});
        else if (node.is_boolean()) node = !node.get<bool>();
        else if (node.is_array()) node = chance(0.5) ? nlohmann::json::array() : nlohmann::json(std::vector<nlohmann::json>(1 + below(50), node.empty() ? nlohmann::json(0) : node[0]));
        break;
      case 5: node = raw(pick<std::string>({"1e400", "-1e400", "1e309", "1e-400", "4.9e-324", "18446744073709551615",
                                            "18446744073709551616", "-9223372036854775809", std::string(400, '7'),
                                            "0." + std::string(400, '0') + "1", "-0", "1E+2", "\"\\ud800\"", "\"\\udc00\\ud800\"",
                                            "\"\\u0000\"", "\"\xff\xfe\"", "NaN", "Infinity", "01", "1.", ".5", "+1", "tru",
                                            "\"\xc0\xaf\""}));
        break;
      case 6: node = std::string(1 + below(20000), 'w'); break;
      default: {  // a deep value, within or just beyond the server's depth limit of 32
        nlohmann::json deep = randomValue();
        for (std::size_t i = 0, n = pick<std::size_t>({5, 30, 31, 32, 33, 64}); i < n; ++i)
          deep = chance(0.5) ? nlohmann::json::array({deep}) : nlohmann::json({{"d", deep}});
        node = deep;
      }
    }
  }

  std::string databaseRef(const Known& known) {
    const std::size_t c = below(10);
    if (c < 3 && !known.databaseJobs.empty()) return pickFrom(known.databaseJobs);
    if (c < 5 && !known.databases.empty()) return pickFrom(known.databases);
    if (c < 6 && !database_.empty()) return database_;
    if (c < 7 && !known.jobs.empty()) return pickFrom(known.jobs);  // maybe a spray job: refused
    return pick<std::string>({"", "/etc/passwd", "../rcfd.sqlite", std::string(32, '0'), "databases/x.h5", "x"});
  }

  /// A job: valid, or made invalid in some of the ways a client can.
  nlohmann::json job(const Known& known) {
    nlohmann::json j = {{"kind", "database"}, {"scene", scene_}, {"seed", seed_++}};
    const std::size_t kind = below(10);
    if (kind >= 7) {
      j["kind"] = kind >= 9 ? "calibration" : "spray";
      j["database"] = databaseRef(known);
      j["duration"] = pick<double>({0.25, 1.0, 0.001, 5.0, 1e-12, 1e300});
      if (j["kind"] == "calibration") {
        j["d0_values"] = chance(0.8) ? nlohmann::json{1e-4, 5e-4} : nlohmann::json{-1.0, 1e-4, 1e-4};
        if (chance(0.5)) j["discard"] = pick<double>({0.0, 0.1, 0.5, 2.0, -1.0});
        if (chance(0.3)) j["calibration"] = {{"parallel", pick<std::string>({"d0_values", "tracers", "both"})},
                                             {"sweep_factor", pick<double>({1.0, 3.0, 1000.0})}};
      }
    }
    if (chance(0.1)) j["checkpoint_interval"] = pick<double>({0.05, 60.0, 0.0, -1.0, 1e-300});
    if (chance(0.08)) {  // a merge patch, sometimes naming a file
      nlohmann::json patch = nlohmann::json::object();
      if (!filePaths_.empty() && chance(0.5)) {
        patch[nlohmann::json::json_pointer(pickFrom(filePaths_))] = pick<std::string>({"/etc/passwd", "x", "", "/proc/self/environ"});
      } else {
        patch[pick<std::string>({"dem", "rcfd", "process", "grid", "nope"})] = randomValue();
      }
      j["scene_patch"] = patch;
    }
    if (chance(0.03)) j["scene_file"] = pick<std::string>({"/etc/passwd", "quick.json", ""});
    if (chance(0.02)) j.erase("scene");
    if (chance(0.03) && !filePaths_.empty())  // a file named inline
      j["scene"][nlohmann::json::json_pointer(pickFrom(filePaths_))] = "/etc/hostname";
    return j;
  }

  std::string jobBody(const Known& known) {
    const std::size_t c = below(100);
    if (c < 40) return jsonText(job(known));  // mostly valid
    if (c < 64) {  // mutated at random pointers
      auto j = job(known);
      for (std::size_t i = 0, n = 1 + below(4); i < n; ++i) mutate(j);
      return dumpWithRaws(j);
    }
    if (c < 68) {  // truncated
      const std::string text = jsonText(job(known), chance(0.5) ? -1 : 2);
      return text.substr(0, below(text.size()));
    }
    if (c < 73) {  // nested: deeper than any scene key, some far deeper (the parser must not recurse)
      const std::size_t depth = pick<std::size_t>({31, 32, 33, 100, 1000, 20000, 150000});
      const bool objects = chance(0.5);
      std::string open, close;
      for (std::size_t i = 0; i < depth; ++i) {
        open += objects ? "{\"a\":" : "[";
        close += objects ? "}" : "]";
      }
      if (chance(0.2)) close.resize(below(close.size()));  // unbalanced
      const std::string inner = open + "1" + close;
      if (chance(0.5)) return inner;
      std::string text = jsonText(job(known));
      text.insert(text.size() - 1, pick<std::string>({",\"scene_patch\":", ",\"x\":", ",\"d0_values\":"}) + inner);
      return text;
    }
    if (c < 78) {  // numbers beyond double range and other number edge cases in valid places
      auto j = job(known);
      j[pick<std::string>({"seed", "duration", "checkpoint_interval"})] =
          raw(pick<std::string>({"1e400", "-1e400", "1e309", "1e-400", "18446744073709551616", "9223372036854775808",
                                 "9223372036854775807", "-9223372036854775808", std::string(300, '9'), "1.0", "-0"}));
      if (chance(0.5)) j["scene"]["process"]["bed_mass"] = raw(pick<std::string>({"1e400", "1e12", "1e-400", "0", "-0.0"}));
      return dumpWithRaws(j);
    }
    if (c < 83) return randomBytes(below(2000));
    if (c < 87) return dumpWithRaws(randomValue());  // JSON, not an object
    if (c < 89) {  // a long array: at, under or over the item limit
      const std::size_t n = pick<std::size_t>({99999, 100000, 100001});
      std::string a = "[";
      for (std::size_t i = 0; i < n; ++i) a += i ? ",0" : "0";
      a += "]";
      std::string text = jsonText(job(known));
      text.insert(text.size() - 1, ",\"d0_values\":" + a);
      return text;
    }
    if (c < 91) {  // a body at the size limit or just over it
      std::string text = jsonText(job(known));
      const std::size_t target = kJsonBodyLimit + (chance(0.5) ? 0 : 1);
      text.insert(text.size() - 1, ",\"description\":\"" + std::string(target - text.size() - 17, 'd') + "\"");
      return text;
    }
    if (c < 94) {  // duplicate keys, BOM, comments, trailing garbage
      const std::string text = jsonText(job(known));
      return pick<std::string>({"\xef\xbb\xbf" + text, text + "x", text + " ", "{\"kind\":\"database\",\"kind\":\"spray\"," + text.substr(1),
                                "/* c */" + text, text + text, std::string(1, '\0') + text, text.substr(0, text.size() - 1) + ",}"});
    }
    if (c < 97) return "";
    return pick<std::string>({"null", "[]", "{}", "\"\"", "0", "true", "{\"kind\":null}", "{\"kind\":\"database\"}",
                              "{\"kind\":\"spray\",\"scene\":{}}", "{\"scene\":[]}", "{\"\":1}"});
  }

  std::string uploadBody() {
    const std::size_t c = below(10);
    if (c < 3 || database_.empty()) return randomBytes(below(4096));
    if (c < 4) return std::string("\x89HDF\r\n\x1a\n", 8) + randomBytes(below(4096));
    std::string file = smallDatabaseBytes();
    if (c < 6) return file;  // valid: 201
    if (c < 8) return file.substr(0, below(file.size()));
    for (std::size_t i = 0, n = 1 + below(8); i < n; ++i) file[below(std::min<std::size_t>(file.size(), 4096))] = char(rng_());
    return file;  // bytes changed in the superblock and the first object headers
  }

  std::string otherBody() {
    if (chance(0.5)) return jsonText(job(Known{}));
    return randomBytes(below(3000));
  }

  std::string randomBytes(std::size_t n) {
    std::string s(n, '\0');
    for (auto& c : s) c = char(rng_());
    return s;
  }

  std::string smallDatabaseBytes() {
    if (databaseBytes_.empty()) {
      std::ifstream in(database_, std::ios::binary);
      databaseBytes_.assign(std::istreambuf_iterator<char>(in), {});
    }
    return databaseBytes_;
  }

  /// Sets the framing headers and writes the bytes.
  void frame(FuzzRequest& r) {
    const std::size_t c = below(100);
    const std::string& body = r.body;
    std::string payload = body;
    if (body.empty()) {
      r.framing = Framing::exact;
      if (c < 20) r.headers.emplace_back("Content-Length", "0");
      else if (c < 22) { r.framing = Framing::badLength; r.headers.emplace_back("Content-Length", pick<std::string>({"-1", "abc", "", "1e3", "0x10", "99999999999999999999999"})); }
      else if (c < 24) { r.framing = Framing::longLength; r.headers.emplace_back("Content-Length", std::to_string(1 + below(100))); }
      else if (c < 26) { r.framing = Framing::overLimit; r.headers.emplace_back("Content-Length", pick<std::string>({"1048577", "9000000000", "18446744073709551615"})); }
    } else if (c < 80) {
      r.framing = Framing::exact;
      r.headers.emplace_back("Content-Length", std::to_string(body.size()));
    } else if (c < 86) {
      r.framing = Framing::chunked;
      r.headers.emplace_back("Transfer-Encoding", "chunked");
      payload = chunkedEncoding(rng_, body);
    } else if (c < 88) {
      r.framing = Framing::badChunked;
      r.headers.emplace_back("Transfer-Encoding", pick<std::string>({"chunked", "gzip, chunked", "chunked, gzip", "identity", "chunked"}));
      if (chance(0.5)) r.headers.emplace_back("Content-Length", std::to_string(body.size()));
      payload = pick<std::string>({"zz\r\n", "ffffffffffffffffff\r\n", "5\r\nab\r\n0\r\n\r\n", "-1\r\n", ""}) + body;
    } else if (c < 91) {
      r.framing = Framing::noLength;  // the body becomes the start of the next request
    } else if (c < 95) {
      r.framing = Framing::shortLength;
      r.headers.emplace_back("Content-Length", std::to_string(below(body.size())));
    } else if (c < 98) {
      r.framing = Framing::longLength;
      r.headers.emplace_back("Content-Length", std::to_string(body.size() + 1 + below(1000)));
    } else {
      r.framing = Framing::badLength;
      if (chance(0.5)) {
        r.headers.emplace_back("Content-Length", std::to_string(body.size()));
        r.headers.emplace_back("Content-Length", std::to_string(body.size() + 1));
      } else {
        r.headers.emplace_back("Content-Length", pick<std::string>({"-1", "abc", " " + std::to_string(body.size()), std::to_string(body.size()) + "x"}));
      }
    }
    std::string wire = r.method + " " + r.target + " " + r.version + "\r\n";
    for (const auto& [name, value] : r.headers) wire += name + ": " + value + "\r\n";
    wire += "\r\n";
    wire += payload;
    r.wire = std::move(wire);
  }

  std::mt19937_64 rng_;
  std::string token_;
  nlohmann::json scene_;
  std::string database_;  ///< path of a small valid field database (uploads), or empty
  std::string databaseBytes_;
  std::vector<std::string> filePaths_;
  std::vector<std::string> raws_;
  int seed_ = 1;
};

// ---------------------------------------------------------------------------------------------
// One connection: write everything, half-close, read every answer until the server closes.

struct Answer {
  const FuzzRequest* request = nullptr;  ///< what it answers, when that is known
  int status = 0;
  std::map<std::string, std::string> headers;  // lower-case names
  std::string body;
  std::string header(const std::string& name) const {
    const auto it = headers.find(name);
    return it == headers.end() ? std::string() : it->second;
  }
};

struct Exchange {
  std::vector<Answer> answers;
  bool timedOut = false;
  std::string error;  ///< answers that could not be parsed, a refused connection
};

Exchange exchange(unsigned short port, const std::vector<FuzzRequest>& requests) {
  Exchange ex;
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(port);
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (fd < 0 || ::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    ex.error = std::string("connect: ") + std::strerror(errno);
    if (fd >= 0) ::close(fd);
    return ex;
  }
  const int one = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  std::string out;
  for (const auto& r : requests) out += r.wire;
  // Write and read together: the server may answer (and stop reading) before the body is all sent.
  const auto deadline = std::chrono::steady_clock::now() + kAnswerTimeout;
  std::string in;
  std::size_t sent = 0;
  bool writing = true, open = true;
  while (open) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
    if (left <= 0) {
      ex.timedOut = true;
      break;
    }
    if (writing && sent == out.size()) {
      ::shutdown(fd, SHUT_WR);  // the server sees the end of the input instead of waiting for more
      writing = false;
    }
    pollfd p{fd, short(POLLIN | (writing ? POLLOUT : 0)), 0};
    if (::poll(&p, 1, int(left)) <= 0) continue;
    if (p.revents & (POLLIN | POLLHUP | POLLERR)) {
      char buffer[65536];
      const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
      if (n > 0) in.append(buffer, std::size_t(n));
      else if (n == 0 || (errno != EINTR && errno != EAGAIN)) open = false;
      if (n <= 0) writing = false;
    }
    if (writing && (p.revents & POLLOUT)) {
      const ssize_t n = ::send(fd, out.data() + sent, out.size() - sent, MSG_NOSIGNAL | MSG_DONTWAIT);
      if (n > 0) sent += std::size_t(n);
      else if (n < 0 && errno != EAGAIN && errno != EINTR) writing = false;  // the server closed its side
    }
  }
  ::close(fd);

  // Answers in order; one to a HEAD request has no body. Answer i is to request i as long as the
  // requests before it were framed as they meant to be: after a Content-Length that lies, the rest
  // is read as the server saw it, answers to requests of its own making, without knowing which are
  // HEADs; then an answer that does not parse is no failure.
  std::size_t offset = 0;
  bool matched = true;
  for (std::size_t i = 0; offset < in.size(); ++i) {
    if (matched && i >= requests.size()) {  // every request framed right, and more answers than requests
      ex.error = "bytes after the last answer: " + printable(in.substr(offset), 400);
      break;
    }
    const FuzzRequest* request = matched ? &requests[i] : nullptr;
    if (request && request->framing != Framing::exact && request->framing != Framing::chunked) matched = false;
    http::response_parser<http::string_body> parser;
    parser.body_limit(std::uint64_t(1) << 32);
    parser.eager(true);
    if (request && request->head()) parser.skip(true);
    boost::beast::error_code ec;
    bool stalled = false;
    while (!parser.is_done()) {
      const std::size_t used = parser.put(boost::asio::buffer(in.data() + offset, in.size() - offset), ec);
      offset += used;
      if (ec == http::error::need_more) ec = {};
      if (ec) break;
      if (used == 0) {  // all there is was given: the answer ends at the end of the input, or never
        stalled = offset < in.size();
        parser.put_eof(ec);
        if (!ec && !parser.is_done()) ec = http::error::partial_message;
        break;
      }
    }
    if (ec || !parser.is_done()) {
      if (request || stalled)
        ex.error = "answer " + std::to_string(i) + " does not parse (" + ec.message() + (stalled ? ", stalled" : "") +
                   "): " + printable(in.substr(offset), 400);
      break;
    }
    Answer a;
    a.request = request;
    a.status = int(parser.get().result_int());
    for (const auto& f : parser.get()) {
      std::string name(f.name_string());
      for (auto& c : name) c = char(std::tolower(static_cast<unsigned char>(c)));
      a.headers[name] = std::string(f.value());
    }
    a.body = parser.get().body();
    ex.answers.push_back(std::move(a));
  }
  return ex;
}

/// Whether the process has ended (it is left a zombie for ServerProcess to reap).
bool hasExited(pid_t pid) {
  siginfo_t info{};
  if (::waitid(P_PID, id_t(pid), &info, WEXITED | WNOHANG | WNOWAIT) != 0) return true;
  return info.si_pid == pid;
}

bool isHexId(const std::string& s) {
  return s.size() == 32 && s.find_first_not_of("0123456789abcdef") == std::string::npos;
}

// ---------------------------------------------------------------------------------------------
// The run: requests, the checks on every answer, and what was accepted.

class FuzzRun {
 public:
  FuzzRun(ServerProcess& server, FuzzSettings settings, long requests, std::string testName, std::string database,
          Known known = {})
      : server_(server),
        settings_(settings),
        requests_(requests),
        testName_(std::move(testName)),
        generator_(settings.seed, server.token(), quickScene(), std::move(database)),
        known_(std::move(known)) {}

  /// Sends the requests; false when it had to stop (the server died, too many failures).
  bool run() {
    long sent = 0;
    while (sent < requests_) {
      auto requests = generator_.connection(known_);
      sent += long(requests.size());
      ++connections_;
      const auto ex = exchange(server_.port(), requests);
      check(requests, ex);
      if (hasExited(server_.pid())) {
        fail(requests, "the server process ended: " + server_.stderrText().substr(0, 3000));
        return false;
      }
      if (failures_ >= 20) {
        ADD_FAILURE() << "stopping after 20 failures; " << settings_.replay(testName_);
        return false;
      }
    }
    return true;
  }

  const std::set<std::string>& accepted() const { return accepted_; }
  const Known& known() const { return known_; }
  std::map<int, long> statusCounts() const { return statusCounts_; }
  const std::map<std::string, long>& problemCounts() const { return problemCounts_; }
  const std::map<std::string, long>& served() const { return served_; }
  long connections() const { return connections_; }

 private:
  void fail(const std::vector<FuzzRequest>& requests, const std::string& what) {
    ++failures_;
    std::string shown;
    for (std::size_t i = 0; i < requests.size(); ++i)
      shown += "--- request " + std::to_string(i) + " ---\n" + printable(requests[i].wire) + "\n";
    ADD_FAILURE() << what << "\nconnection " << connections_ << " of seed " << settings_.seed << "; "
                  << settings_.replay(testName_) << "\n" << shown;
  }

  void check(const std::vector<FuzzRequest>& requests, const Exchange& ex) {
    if (ex.timedOut) fail(requests, "no answer within " + std::to_string(kAnswerTimeout.count()) + " s (a hang)");
    if (!ex.error.empty()) fail(requests, ex.error);
    if (ex.answers.empty() && !ex.timedOut && ex.error.empty())
      fail(requests, "the connection closed without an answer");
    if (ex.answers.size() > requests.size() + 8)  // bodies read as requests may add a few
      fail(requests, std::to_string(ex.answers.size()) + " answers to " + std::to_string(requests.size()) + " requests");
    for (const Answer& a : ex.answers) {
      ++statusCounts_[a.status];
      checkAnswer(requests, a, a.request);
    }
  }

  void checkAnswer(const std::vector<FuzzRequest>& requests, const Answer& a, const FuzzRequest* r) {
    if (a.status >= 500) return fail(requests, "status " + std::to_string(a.status) + ": " + printable(a.body, 600));
    if (a.status < 100) return fail(requests, "status " + std::to_string(a.status));
    const bool success = a.status >= 200 && a.status < 300;
    if (!success && !a.body.empty()) {
      if (a.header("content-type") != "application/problem+json")
        return fail(requests, "error " + std::to_string(a.status) + " with Content-Type \"" + a.header("content-type") + "\"");
      const auto p = nlohmann::json::parse(a.body, nullptr, false);
      const auto nonEmpty = [&](const char* key) {
        return p.is_object() && p.contains(key) && p[key].is_string() && !p[key].get<std::string>().empty();
      };
      if (!nonEmpty("type") || !nonEmpty("title") || !nonEmpty("instance"))
        return fail(requests, "problem without type, title or instance: " + printable(a.body, 600));
      ++problemCounts_[p["type"].get<std::string>().substr(p["type"].get<std::string>().rfind(':') + 1)];
      if (!p.contains("status") || p["status"] != a.status)
        return fail(requests, "problem status differs from " + std::to_string(a.status) + ": " + printable(a.body, 600));
    }
    if (success && a.header("content-type").rfind("application/json", 0) == 0 && !(r && r->head())) {
      if (nlohmann::json::parse(a.body, nullptr, false).is_discarded())
        return fail(requests, "a 2xx JSON body that does not parse: " + printable(a.body, 600));
    }
    if (r && success && r->unauthorized) {
      // Public: health and the web page's static files (docs/web.md), which hold no data.
      const std::string path = r->target.substr(0, r->target.find('?'));
      const bool page = path == "/" || (path.rfind("/web/", 0) == 0 && path.find('/', 5) == std::string::npos);
      const bool open = r->method == "GET" && (path == "/v1/health" || path == "/v1/health/" || page);
      if (!open) return fail(requests, "answered " + std::to_string(a.status) + " without the token");
    }
    learn(requests, a, r);
  }

  /// What the answer tells about the server's state: accepted jobs, uploaded databases, page tokens.
  void learn(const std::vector<FuzzRequest>& requests, const Answer& a, const FuzzRequest* r) {
    const bool success = a.status >= 200 && a.status < 300;
    if (!success) return;
    if (r && r->method == "GET") {  // which read routes served something
      const auto s = segmentsOf(r->target);
      if (s.size() == 4 && s[1] == "jobs") ++served_[s[3]];
      if (s.size() == 5 && s[3] == "artifacts") ++served_["artifact " + s[4]];
    }
    const std::string location = a.header("location");
    if (location.rfind("/v1/jobs/", 0) == 0) {
      const auto body = nlohmann::json::parse(a.body, nullptr, false);
      const std::string id = location.substr(9);
      if (!isHexId(id) || !body.is_object() || body.value("id", "") != id)
        return fail(requests, "a submit answered with Location " + location + " and " + printable(a.body, 400));
      if (r && !r->submitRoute) return fail(requests, "Location of a new job in the answer to another route");
      const bool replayed = a.header("idempotent-replayed") == "true";
      if (replayed && !accepted_.count(id))
        return fail(requests, "an idempotent replay of a job never accepted: " + id);
      if (accepted_.insert(id).second) {
        known_.jobs.push_back(id);
        if (body.value("kind", "") == "database") known_.databaseJobs.push_back(id);
      }
    } else if (location.rfind("/v1/databases/", 0) == 0) {
      const std::string id = location.substr(14);
      if (!isHexId(id)) return fail(requests, "an upload answered with Location " + location);
      known_.databases.push_back(id);
    } else if (r && r->submitRoute && r->framing == Framing::exact) {
      return fail(requests, "a submit answered " + std::to_string(a.status) + " without a Location");
    }
    if (a.body.find("next_page_token") != std::string::npos) {
      const auto body = nlohmann::json::parse(a.body, nullptr, false);
      if (body.is_object() && body.contains("next_page_token") && body["next_page_token"].is_string() &&
          known_.pageTokens.size() < 50)
        known_.pageTokens.push_back(body["next_page_token"]);
    }
  }

  ServerProcess& server_;
  FuzzSettings settings_;
  long requests_;
  std::string testName_;
  RequestGenerator generator_;
  Known known_;
  std::set<std::string> accepted_;
  std::map<int, long> statusCounts_;
  std::map<std::string, long> problemCounts_;
  std::map<std::string, long> served_;
  long connections_ = 0;
  int failures_ = 0;
};

// ---------------------------------------------------------------------------------------------
// Checks after a run.

/// Every job GET /v1/jobs lists, following next_page_token.
std::set<std::string> listedJobs(const ServerProcess& server, std::map<std::string, std::string>* states = nullptr) {
  std::set<std::string> ids;
  std::string token;
  for (int page = 0; page < 1000; ++page) {
    const auto r = server.get("/v1/jobs?page_size=" + std::to_string(page % 2 ? 1000 : 37) +
                              (token.empty() ? "" : "&page_token=" + token));
    EXPECT_EQ(r.status, 200) << r.body;
    if (r.status != 200) break;
    const auto body = r.json();
    for (const auto& job : body.at("jobs")) {
      EXPECT_TRUE(ids.insert(job.at("id").get<std::string>()).second) << "listed twice: " << job.at("id");
      if (states) (*states)[job.at("id")] = job.at("state");
    }
    if (!body.contains("next_page_token")) break;
    token = body["next_page_token"];
  }
  return ids;
}

/// Runs `sql` on a read-only connection of the test's own; every row's first column as text.
std::vector<std::string> sqliteRows(const std::filesystem::path& db, const std::string& sql) {
  std::vector<std::string> rows;
  sqlite3* handle = nullptr;
  if (sqlite3_open_v2(db.c_str(), &handle, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    ADD_FAILURE() << "cannot open " << db << ": " << (handle ? sqlite3_errmsg(handle) : "");
    sqlite3_close(handle);
    return rows;
  }
  sqlite3_busy_timeout(handle, 5000);
  sqlite3_stmt* stmt = nullptr;
  if (sqlite3_prepare_v2(handle, sql.c_str(), -1, &stmt, nullptr) != SQLITE_OK) {
    ADD_FAILURE() << sql << ": " << sqlite3_errmsg(handle);
  } else {
    int rc;
    while ((rc = sqlite3_step(stmt)) == SQLITE_ROW) {
      const auto* text = sqlite3_column_text(stmt, 0);
      rows.emplace_back(text ? reinterpret_cast<const char*>(text) : "NULL");
    }
    if (rc != SQLITE_DONE) ADD_FAILURE() << sql << ": " << sqlite3_errmsg(handle);
  }
  sqlite3_finalize(stmt);
  sqlite3_close(handle);
  return rows;
}

void expectDatabaseIntact(const std::filesystem::path& db, const std::set<std::string>& jobs) {
  EXPECT_EQ(sqliteRows(db, "PRAGMA integrity_check"), std::vector<std::string>{"ok"});
  EXPECT_TRUE(sqliteRows(db, "PRAGMA foreign_key_check").empty());
  const auto rows = sqliteRows(db, "SELECT id FROM jobs");
  EXPECT_EQ(std::set<std::string>(rows.begin(), rows.end()), jobs);
  // Every job has its "submitted" event, first.
  EXPECT_EQ(sqliteRows(db, "SELECT COUNT(*) FROM jobs WHERE NOT EXISTS (SELECT 1 FROM job_events e WHERE "
                           "e.job_id = jobs.id AND e.from_state IS NULL AND e.to_state = 'QUEUED')"),
            std::vector<std::string>{"0"});
}

template <class Key>
std::string statusSummary(const std::map<Key, long>& counts) {
  std::ostringstream out;
  for (const auto& [status, n] : counts) out << status << ": " << n << "  ";
  return out.str();
}

/// The server is alive, answers health, lists exactly `expected`, and its database is intact before
/// and after a clean stop.
void expectHealthyAfter(ServerProcess& server, const std::filesystem::path& dataDir,
                        const std::set<std::string>& expected, const std::set<std::string>& allowedStates) {
  ASSERT_FALSE(hasExited(server.pid())) << server.stderrText();
  const auto health = httpRequest(server.port(), http::verb::get, "/v1/health");
  EXPECT_EQ(health.status, 200);
  EXPECT_EQ(nlohmann::json::parse(health.body, nullptr, false).value("status", ""), "ok");
  std::map<std::string, std::string> states;
  const auto listed = listedJobs(server, &states);
  EXPECT_EQ(listed, expected) << "listed " << listed.size() << ", accepted " << expected.size();
  for (const auto& [id, state] : states) EXPECT_TRUE(allowedStates.count(state)) << id << " is " << state;
  int checked = 0;
  for (const auto& id : expected) {
    if (++checked > 40) break;
    EXPECT_EQ(server.get("/v1/jobs/" + id).status, 200) << id;
  }
  const auto db = dataDir / "rcfd.sqlite";
  expectDatabaseIntact(db, expected);  // while the server runs (WAL readers see a consistent state)
  const int status = server.stop(SIGTERM);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "exit status " << status;
  expectDatabaseIntact(db, expected);
  // An upload cut short leaves no partial file behind.
  std::size_t partial = 0;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dataDir / "databases" / "incoming", ec))
    partial += entry.path().extension() == ".part";
  EXPECT_EQ(partial, 0u);
}

std::string currentTestName() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  return std::string(info->test_suite_name()) + "." + info->name();
}

}  // namespace

TEST(ServerFuzz, TheGeneratorIsDeterministicFromItsSeed) {
  const auto bytes = [](std::uint64_t seed) {
    RequestGenerator generator(seed, kToken, quickScene(), "");
    Known known;
    known.jobs = {std::string(32, 'a')};
    std::string all;
    for (int i = 0; i < 200; ++i)
      for (const auto& r : generator.connection(known)) all += r.wire;
    return all;
  };
  EXPECT_EQ(bytes(7), bytes(7));
  EXPECT_NE(bytes(7), bytes(8));
}

TEST(ServerFuzz, RandomRequestsGetNo5xxAndLeaveTheServerHealthyWithItsDatabaseIntact) {
  const auto settings = FuzzSettings::fromEnvironment();
  TempDir dir;
  const auto data = dir.path() / "data";
  // Uploads: a database on a coarse grid (a few hundred KiB; the first 4 KiB, where the fuzzer
  // changes bytes, hold the HDF5 superblock, object headers and the global heap all the same).
  auto coarse = quickScene();
  coarse["grid"]["cell_size"] = 0.0125;
  writeSmallDatabase(coarse, dir.path() / "upload.h5");
  // --workers 0: accepted jobs stay QUEUED, no solver runs. An upload that sends HDF5 into an endless
  // loop is refused after --upload-check-timeout: shorter here than the fuzzer's wait for an answer.
  ServerProcess server(data, kToken, {"--workers", "0", "--upload-check-timeout", kUploadCheckSeconds});
  const auto t0 = std::chrono::steady_clock::now();
  FuzzRun run(server, settings, settings.requests, currentTestName(), (dir.path() / "upload.h5").string());
  const bool completed = run.run();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "[ fuzz     ] seed " << settings.seed << ", " << settings.requests << " requests on "
            << run.connections() << " connections in " << seconds << " s; " << run.accepted().size()
            << " jobs accepted, " << run.known().databases.size() << " databases uploaded\n"
            << "[ fuzz     ] statuses " << statusSummary(run.statusCounts()) << "\n"
            << "[ fuzz     ] problems " << statusSummary(run.problemCounts()) << std::endl;
  ASSERT_TRUE(completed) << settings.replay(currentTestName());
  // Enough of each kind of answer that the run tested something (a shorter run may miss some).
  const auto counts = run.statusCounts();
  if (settings.requests >= kDefaultRequests) {
    EXPECT_GT(run.accepted().size(), 20u) << "too few valid submits";
    for (const int status : {200, 201, 202, 400, 401, 404, 405, 409, 413, 415, 422, 431})
      EXPECT_GT(counts.count(status) ? counts.at(status) : 0, 0) << "no " << status << " seen";
  }
  expectHealthyAfter(server, data, run.accepted(), {"QUEUED", "CANCELLED"});
  if (HasFailure()) std::cout << settings.replay(currentTestName()) << std::endl;
}

// The same fuzzing with a SUCCEEDED spray job and an uploaded database to aim at: result, coverage
// (json, csv, an HDF5 export per request), artifacts and the job's own job.json are then served
// rather than refused. One real run of the solver (a small database, 200 tracers, 0.25 s).
TEST(ServerFuzz, RoutesOfASucceededSprayJobGetNo5xxEither) {
  if (!std::filesystem::exists(binaryDir() / "rcfd-solve")) GTEST_SKIP() << "build rcfd-solve first";
  const auto settings = FuzzSettings::fromEnvironment();
  TempDir dir;
  const auto data = dir.path() / "data";
  const auto scene = withTracers(quickScene(), 200);
  writeSmallDatabase(scene, dir.path() / "db.h5");
  std::string database, spray;
  std::vector<std::string> artifacts;
  {
    ServerProcess server(data, kToken,
                         {"--workers", "1", "--solver", (binaryDir() / "rcfd-solve").string(), "--worker-nice", "0"});
    std::ifstream in(dir.path() / "db.h5", std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), {});
    const auto uploaded = server.post("/v1/databases", bytes, {{"Content-Type", "application/octet-stream"}});
    ASSERT_EQ(uploaded.status, 201) << uploaded.body;
    database = uploaded.json().at("id");
    const nlohmann::json job = {{"kind", "spray"}, {"scene", scene}, {"database", database},
                                {"duration", 0.25}, {"seed", 1}, {"checkpoint_interval", 0.05}};
    const auto submitted = server.post("/v1/jobs", job.dump());
    ASSERT_EQ(submitted.status, 202) << submitted.body;
    spray = submitted.json().at("id");
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(180);
    std::string state;
    while (std::chrono::steady_clock::now() < deadline) {
      state = server.get("/v1/jobs/" + spray).json().at("state");
      if (state == "SUCCEEDED" || state == "FAILED" || state == "CANCELLED") break;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    ASSERT_EQ(state, "SUCCEEDED") << server.get("/v1/jobs/" + spray).body;
    artifacts = server.get("/v1/jobs/" + spray).json().at("artifacts").get<std::vector<std::string>>();
  }
  auto coarse = quickScene();  // the fuzzer's uploads: a small file, as in the test above
  coarse["grid"]["cell_size"] = 0.0125;
  writeSmallDatabase(coarse, dir.path() / "upload.h5");
  // Restarted with --workers 0: what the fuzzer submits stays QUEUED.
  ServerProcess server(data, kToken, {"--workers", "0", "--upload-check-timeout", kUploadCheckSeconds});
  Known known;
  known.finishedJob = spray;
  known.jobs = {spray};
  known.databases = {database};
  known.artifacts = artifacts;
  const auto t0 = std::chrono::steady_clock::now();
  FuzzRun run(server, settings, settings.scaled(1500), currentTestName(), (dir.path() / "upload.h5").string(), known);
  const bool completed = run.run();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "[ fuzz     ] seed " << settings.seed << ", " << settings.scaled(1500) << " requests on "
            << run.connections() << " connections in " << seconds << " s; statuses "
            << statusSummary(run.statusCounts()) << "\n"
            << "[ fuzz     ] problems " << statusSummary(run.problemCounts()) << "\n"
            << "[ fuzz     ] served " << statusSummary(run.served()) << std::endl;
  ASSERT_TRUE(completed) << settings.replay(currentTestName());
  if (settings.requests >= kDefaultRequests) {
    for (const char* what : {"result", "coverage", "events", "artifact result.h5", "artifact job.json"})
      EXPECT_TRUE(run.served().count(what)) << "never served: " << what;
  }
  auto expected = run.accepted();
  expected.insert(spray);
  expectHealthyAfter(server, data, expected, {"QUEUED", "CANCELLED", "SUCCEEDED"});
  if (HasFailure()) std::cout << settings.replay(currentTestName()) << std::endl;
}

// Found by the fuzz test: the answer to a HEAD request carried the body of the problem (405, 401,
// 400, 431), so on a kept-alive connection the next answer was read from those bytes.
TEST(ServerFuzz, AnAnswerToHeadHasNoBodySoTheNextAnswerOnTheConnectionIsReadRight) {
  TempDir dir;
  ServerProcess server(dir.path() / "data", kToken);
  const std::string auth = std::string("Authorization: Bearer ") + kToken + "\r\n";
  const auto request = [](const std::string& method, const std::string& wire) {
    FuzzRequest r;
    r.method = method;
    r.wire = wire;
    return r;
  };
  const auto kept = exchange(server.port(), {request("HEAD", "HEAD /v1/jobs HTTP/1.1\r\nHost: a\r\n" + auth + "\r\n"),
                                             request("GET", "GET /v1/health HTTP/1.1\r\nHost: a\r\n\r\n")});
  ASSERT_TRUE(kept.error.empty()) << kept.error;
  ASSERT_EQ(kept.answers.size(), 2u);
  EXPECT_EQ(kept.answers[0].status, 405);
  EXPECT_EQ(kept.answers[0].header("allow"), "GET, POST");
  EXPECT_EQ(kept.answers[0].header("content-type"), "application/problem+json");
  EXPECT_EQ(kept.answers[1].status, 200);
  EXPECT_EQ(nlohmann::json::parse(kept.answers[1].body, nullptr, false).value("status", ""), "ok");
  // Answers after which the server closes the connection: nothing follows their header either.
  const std::vector<std::pair<int, std::string>> closing = {
      {401, "HEAD /v1/jobs HTTP/1.1\r\nHost: a\r\n\r\n"},
      {400, "HEAD /v1/jobs HTTP/1.1\r\nHost: a\r\n" + auth + "no colon here\r\n\r\n"},
      {431, "HEAD /v1/jobs HTTP/1.1\r\nHost: a\r\n" + auth + "X-Padding: " + std::string(17000, 'p') + "\r\n\r\n"},
  };
  for (const auto& [status, wire] : closing) {
    const auto ex = exchange(server.port(), {request("HEAD", wire)});
    EXPECT_TRUE(ex.error.empty()) << status << ": " << ex.error;
    ASSERT_EQ(ex.answers.size(), 1u) << status;
    EXPECT_EQ(ex.answers[0].status, status);
    EXPECT_NE(ex.answers[0].header("content-length"), "") << status;
  }
  EXPECT_FALSE(hasExited(server.pid()));
}

namespace {

/// The small database with the first object of its HDF5 global heap (the scene's JSON text, read as a
/// variable-length string) damaged as the fuzz test's byte changes did: HDF5 1.10 trusts the object's
/// header. `loop`: index 0 and size 0, a free-space entry the heap reader never moves past; otherwise
/// a size of 17 TiB, copied out of a 4 KiB heap.
std::string damagedDatabase(const std::filesystem::path& valid, bool loop) {
  std::ifstream in(valid, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), {});
  const auto heap = bytes.find("GCOL");
  if (heap == std::string::npos) throw std::runtime_error("no global heap in " + valid.string());
  const std::size_t object = heap + 16;  // after "GCOL", version, reserved, collection size
  const std::uint64_t size = loop ? 0 : 0x0000110000000000ull;
  if (loop) bytes[object] = bytes[object + 1] = '\0';  // heap object index 0
  for (int i = 0; i < 8; ++i) bytes[object + 8 + std::size_t(i)] = char((size >> (8 * i)) & 0xff);
  return bytes;
}

FuzzRequest uploadRequest(const std::string& body) {
  FuzzRequest r;
  r.method = "POST";
  r.wire = std::string("POST /v1/databases HTTP/1.1\r\nHost: a\r\nAuthorization: Bearer ") + kToken +
           "\r\nContent-Type: application/x-hdf5\r\nContent-Length: " + std::to_string(body.size()) + "\r\n\r\n" + body;
  return r;
}

}  // namespace

// Found by the fuzz test (seeds 101 and 102 at 20000 requests): an upload with a damaged HDF5 global
// heap killed the server (SIGSEGV in H5HG_read), or sent the thread validating it into an endless loop
// holding the server's HDF5 lock, after which every upload and coverage export hung. Uploads are now
// read by a child process, killed after --upload-check-timeout.
TEST(ServerFuzz, AnUploadThatCrashesOrHangsTheHdf5ReaderIs422AndTheServerGoesOn) {
  TempDir dir;
  writeSmallDatabase(quickScene(), dir.path() / "db.h5");
  const auto data = dir.path() / "data";
  ServerProcess server(data, kToken, {"--workers", "0", "--upload-check-timeout", "2"});
  for (const bool loop : {false, true}) {
    const auto ex = exchange(server.port(), {uploadRequest(damagedDatabase(dir.path() / "db.h5", loop))});
    ASSERT_FALSE(ex.timedOut) << (loop ? "looping" : "crashing") << " upload: no answer";
    ASSERT_EQ(ex.answers.size(), 1u) << ex.error << "; server alive: " << !hasExited(server.pid());
    const auto& a = ex.answers[0];
    EXPECT_EQ(a.status, 422) << a.body;
    const auto p = nlohmann::json::parse(a.body, nullptr, false);
    EXPECT_EQ(p.value("type", ""), "urn:rcfd:problem:invalid-database") << a.body;
    EXPECT_NE(p.value("detail", "").find(loop ? "did not end within 2 s" : "crashed the HDF5 library"), std::string::npos)
        << a.body;
    ASSERT_FALSE(hasExited(server.pid())) << server.stderrText();
  }
  std::ifstream in(dir.path() / "db.h5", std::ios::binary);
  const std::string valid((std::istreambuf_iterator<char>(in)), {});
  const auto ok = exchange(server.port(), {uploadRequest(valid)});
  ASSERT_EQ(ok.answers.size(), 1u) << ok.error;
  EXPECT_EQ(ok.answers[0].status, 201) << ok.answers[0].body;
  EXPECT_EQ(httpRequest(server.port(), http::verb::get, "/v1/health").status, 200);
  std::size_t kept = 0, partial = 0;
  for (const auto& entry : std::filesystem::directory_iterator(data / "databases"))
    kept += entry.path().extension() == ".h5";
  for (auto it = std::filesystem::directory_iterator(data / "databases" / "incoming");
       it != std::filesystem::directory_iterator(); ++it)
    ++partial;
  EXPECT_EQ(kept, 1u);
  EXPECT_EQ(partial, 0u);
  const int status = server.stop(SIGTERM);  // no thread of the server is left looping in HDF5
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "exit status " << status;
}
