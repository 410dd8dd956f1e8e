// The OpenAPI 3.1 document at /v1/openapi.json against a real rcfd-server: its structure (every reference
// resolves, every path parameter is declared, the request body of a job is the job schema the server
// validates with), every route it documents answers on the server, and on the paths it documents the
// server answers no method it leaves out.

#include <gtest/gtest.h>

#include <cctype>
#include <fstream>
#include <regex>
#include <set>
#include <string>

#include "OpenApi.hpp"
#include "ServerFixture.hpp"

using namespace rcfd::test;
namespace http = boost::beast::http;

namespace {

constexpr const char* kToken = "test-token-openapi";

/// The value at an RFC 6901 pointer of "#/a/b" form, or null.
const nlohmann::json* resolve(const nlohmann::json& doc, const std::string& ref) {
  if (ref.rfind("#/", 0) != 0) return nullptr;
  const nlohmann::json::json_pointer pointer(ref.substr(1));
  return doc.contains(pointer) ? &doc.at(pointer) : nullptr;
}

void collectReferences(const nlohmann::json& node, std::vector<std::string>& out) {
  if (node.is_object()) {
    for (const auto& [key, value] : node.items()) {
      if (key == "$ref" && value.is_string()) out.push_back(value.get<std::string>());
      collectReferences(value, out);
    }
  } else if (node.is_array()) {
    for (const auto& value : node) collectReferences(value, out);
  }
}

/// A concrete path for a template: ids of no resource, the scene schema, an artifact name.
std::string concrete(std::string path) {
  const std::string id(32, 'a');
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{
           {"{id}", id},
           {"{name}", path.find("schemas") != std::string::npos    ? "scene"
                      : path.find("examples") != std::string::npos ? "quick"
                      : path.find("web") != std::string::npos      ? "app.js"
                                                                   : "summary.json"}}) {
    for (auto at = path.find(from); at != std::string::npos; at = path.find(from)) path.replace(at, from.size(), to);
  }
  return path;
}

/// Whether a reply is the router's "no such route" (not a resource that is not there).
bool isNoRoute(const Reply& r) {
  return r.status == 404 && r.json().value("type", std::string()) == "urn:rcfd:problem:not-found";
}

/// The verb of an OpenAPI (lower-case) method name.
http::verb verbOf(std::string method) {
  for (char& c : method) c = char(std::toupper(static_cast<unsigned char>(c)));
  return http::string_to_verb(method);
}

class OpenApi : public ::testing::Test {
 protected:
  void SetUp() override {
    data_ = std::make_unique<TempDir>();
    server_ = std::make_unique<ServerProcess>(data_->path() / "data", kToken);
  }
  Reply request(http::verb method, const std::string& target, const std::string& body = {}) {
    return httpRequest(server_->port(), method, target, kToken, body);
  }
  nlohmann::json document() {
    const Reply r = request(http::verb::get, "/v1/openapi.json");
    EXPECT_EQ(r.status, 200) << r.body;
    EXPECT_EQ(r.header("content-type"), "application/json");
    return r.json();
  }
  std::unique_ptr<TempDir> data_;
  std::unique_ptr<ServerProcess> server_;
};

}  // namespace

TEST_F(OpenApi, TheDocumentIsOpenApi31WhoseReferencesAndParametersHold) {
  const nlohmann::json doc = document();
  EXPECT_EQ(doc.at("openapi"), "3.1.0");
  EXPECT_EQ(doc.at("info").at("version"), RCFD_VERSION);
  EXPECT_FALSE(doc.at("info").at("title").get<std::string>().empty());
  std::vector<std::string> references;
  collectReferences(doc, references);
  ASSERT_FALSE(references.empty());
  for (const auto& ref : references) EXPECT_NE(resolve(doc, ref), nullptr) << ref;
  std::set<std::string> operationIds;
  for (const auto& [path, item] : doc.at("paths").items()) {
    for (const auto& [method, op] : item.items()) {
      EXPECT_TRUE(operationIds.insert(op.at("operationId").get<std::string>()).second) << path;
      EXPECT_FALSE(op.at("responses").empty()) << method << " " << path;
      std::set<std::string> declared;
      for (const auto& p : op.value("parameters", nlohmann::json::array())) {
        if (p.at("in") == "path") declared.insert(p.at("name").get<std::string>());
      }
      std::set<std::string> inPath;
      for (auto at = path.find('{'); at != std::string::npos; at = path.find('{', at + 1))
        inPath.insert(path.substr(at + 1, path.find('}', at) - at - 1));
      EXPECT_EQ(declared, inPath) << method << " " << path;
    }
  }
  // The job a client posts is the job schema the server serves and validates with.
  const auto& submit = doc.at("paths").at("/v1/jobs").at("post");
  const auto* job = resolve(doc, submit.at("requestBody").at("content").at("application/json").at("schema").at("$ref"));
  ASSERT_NE(job, nullptr);
  const nlohmann::json served = request(http::verb::get, "/v1/schemas/job").json();
  EXPECT_EQ(job->at("properties").size(), served.at("properties").size());
  // Query parameters where docs/api.md names them.
  auto queryNames = [&](const std::string& path) {
    std::set<std::string> names;
    for (const auto& p : doc.at("paths").at(path).at("get").value("parameters", nlohmann::json::array()))
      if (p.at("in") == "query") names.insert(p.at("name").get<std::string>());
    return names;
  };
  EXPECT_EQ(queryNames("/v1/jobs"), (std::set<std::string>{"state", "kind", "owner", "page_size", "page_token"}));
  EXPECT_EQ(queryNames("/v1/jobs/{id}/coverage"), (std::set<std::string>{"format", "bins"}));
  // Only health and the web page's static files are answered without the token.
  for (const auto& [path, item] : doc.at("paths").items()) {
    for (const auto& [method, op] : item.items()) {
      const bool open = op.contains("security") && op.at("security").empty();
      EXPECT_EQ(open, path == "/v1/health" || path == "/" || path == "/web/{name}") << method << " " << path;
    }
  }
}

// docs/api.md documents each route under a heading "### `METHOD PATH`": the same routes as the document.
TEST_F(OpenApi, TheDocumentHasTheRoutesOfTheApiReference) {
  std::ifstream in(std::string(RCFD_SOURCE_DIR) + "/docs/api.md");
  ASSERT_TRUE(in) << "docs/api.md";
  std::set<std::string> reference, documented;
  const std::regex heading("^### `(GET|POST) (/[^ `?]*)");
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (!std::regex_search(line, m, heading)) continue;
    std::string path = std::regex_replace(m[2].str(), std::regex("\\{[a-z]+\\|[a-z|]+\\}"), "{name}");
    std::string method = m[1].str();
    for (char& c : method) c = char(std::tolower(static_cast<unsigned char>(c)));
    reference.insert(method + " " + path);
  }
  const nlohmann::json doc = document();
  for (const auto& [path, item] : doc.at("paths").items())
    for (const auto& [method, op] : item.items()) documented.insert(method + " " + path);
  EXPECT_EQ(documented, reference);
}

TEST_F(OpenApi, EveryDocumentedRouteAnswersAndNoOtherMethodDoes) {
  const nlohmann::json doc = document();
  const std::vector<std::string> methods = {"get", "post", "put", "delete", "patch"};
  int routes = 0;
  for (const auto& [path, item] : doc.at("paths").items()) {
    const std::string target = concrete(path);
    for (const auto& method : methods) {
      const Reply r = request(verbOf(method), target, method == "post" ? "{}" : "");
      if (item.contains(method)) {
        ++routes;
        EXPECT_FALSE(isNoRoute(r)) << method << " " << target << ": " << r.body;
        EXPECT_NE(r.status, 405) << method << " " << target << ": " << r.body;
      } else {
        EXPECT_TRUE(r.status == 405 || isNoRoute(r)) << method << " " << target << " answered " << r.status << ": " << r.body;
      }
    }
  }
  EXPECT_EQ(routes, int(rcfd::server::routeSpecs().size()));
  // Paths beside the documented ones are no routes.
  const std::string id(32, 'a');
  for (const std::string& target : std::vector<std::string>{"/v1/jobs/" + id + "/nothing", "/v1/other", "/v2/jobs",
                                                            "/v1/databases/" + id + "/x"}) {
    EXPECT_TRUE(isNoRoute(request(http::verb::get, target))) << target;
  }
}
