// The web page's routes against a real rcfd-server: GET / and every file of the page answer without the
// token, with their media type, the page's Content-Security-Policy and X-Content-Type-Options; the page
// loads no inline script or style and no resource from elsewhere; nothing else became public (every
// data route still answers 401 without the token); and the examples the page starts from are the
// repository's scenes.

#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <set>

#include "OpenApi.hpp"
#include "ServerFixture.hpp"
#include "WebFiles.hpp"
#include "WebPage.hpp"

using namespace rcfd::test;
namespace http = boost::beast::http;

namespace {

constexpr const char* kToken = "test-token-web";

class WebPage : public ::testing::Test {
 protected:
  void SetUp() override {
    data_ = std::make_unique<TempDir>();
    server_ = std::make_unique<ServerProcess>(data_->path() / "data", kToken);
  }
  /// A request as a browser loading the page sends it: no Authorization header.
  Reply anonymous(http::verb method, const std::string& target) const {
    return httpRequest(server_->port(), method, target);
  }
  static void expectPageHeaders(const Reply& r, const std::string& contentType, const std::string& what) {
    EXPECT_EQ(r.status, 200) << what << ": " << r.body;
    EXPECT_EQ(r.header("content-type"), contentType) << what;
    EXPECT_EQ(r.header("content-security-policy"), std::string(rcfd::server::kWebContentSecurityPolicy)) << what;
    EXPECT_EQ(r.header("x-content-type-options"), "nosniff") << what;
    EXPECT_EQ(r.header("referrer-policy"), "no-referrer") << what;
    EXPECT_EQ(r.header("www-authenticate"), "") << what;
  }
  std::unique_ptr<TempDir> data_;
  std::unique_ptr<ServerProcess> server_;
};

/// The page's files by the name they are served under (/web/NAME).
std::map<std::string, std::string> pageFiles() {
  std::map<std::string, std::string> out;
  for (const auto& [path, text] : rcfd::server::webFiles()) out[path.substr(path.rfind('/') + 1)] = std::string(text);
  return out;
}

}  // namespace

TEST_F(WebPage, ThePolicyAllowsOnlyThisServerAndBlobImages) {
  const std::string policy(rcfd::server::kWebContentSecurityPolicy);
  for (const char* directive : {"default-src 'self'", "script-src 'self'", "style-src 'self'", "img-src 'self' blob:",
                                "connect-src 'self'", "object-src 'none'", "base-uri 'none'", "frame-ancestors 'none'"})
    EXPECT_NE(policy.find(directive), std::string::npos) << directive;
  for (const char* loose : {"unsafe-inline", "unsafe-eval", "data:", "*", "http:", "https:"})
    EXPECT_EQ(policy.find(loose), std::string::npos) << loose;
}

TEST_F(WebPage, TheRootServesTheHtmlWithoutTheTokenAndWithItsHeaders) {
  const Reply page = anonymous(http::verb::get, "/");
  expectPageHeaders(page, "text/html; charset=utf-8", "GET /");
  EXPECT_EQ(page.body, pageFiles().at("index.html"));
  // The same with a token and with a query (the page's state lives in the fragment, never sent).
  expectPageHeaders(httpRequest(server_->port(), http::verb::get, "/?x=1", kToken), "text/html; charset=utf-8", "GET /?x=1");
  // Scripts come from files of this server only: every <script> has a src under /web/, and no element
  // carries an inline style or event handler.
  const std::regex script("<script([^>]*)>");
  int scripts = 0;
  for (auto it = std::sregex_iterator(page.body.begin(), page.body.end(), script); it != std::sregex_iterator(); ++it) {
    ++scripts;
    EXPECT_NE((*it)[1].str().find("src=\"/web/"), std::string::npos) << (*it)[0];
  }
  EXPECT_EQ(scripts, 1);
  EXPECT_FALSE(std::regex_search(page.body, std::regex("\\sstyle\\s*=|\\son[a-z]+\\s*=|<style", std::regex::icase)));
  EXPECT_FALSE(std::regex_search(page.body, std::regex("(src|href)=\"(https?:)?//", std::regex::icase)))
      << "a resource from another server";
}

TEST_F(WebPage, EveryFileOfThePageIsServedWithItsMediaTypeAndHeaders) {
  const std::map<std::string, std::string> types = {{".html", "text/html; charset=utf-8"},
                                                    {".css", "text/css; charset=utf-8"},
                                                    {".js", "text/javascript; charset=utf-8"},
                                                    {".svg", "image/svg+xml"}};
  const auto files = pageFiles();
  ASSERT_GE(files.size(), 5u);
  for (const char* name : {"index.html", "app.js", "api.js", "chart.js", "app.css"}) EXPECT_TRUE(files.count(name)) << name;
  for (const auto& [name, text] : files) {
    const std::string type = types.at(name.substr(name.rfind('.')));
    const Reply r = anonymous(http::verb::get, "/web/" + name);
    expectPageHeaders(r, type, name);
    EXPECT_EQ(r.body, text) << name;
    if (name.ends_with(".js")) {
      // No HTML parsing of strings and no code from strings: text reaches the page as text.
      for (const char* risky : {"innerHTML", "outerHTML", "insertAdjacentHTML", "document.write", "eval(", "new Function",
                                "setAttribute('style'", "localStorage"})
        EXPECT_EQ(text.find(risky), std::string::npos) << name << " uses " << risky;
    }
  }
}

TEST_F(WebPage, NamesOutsideThePageAreNotFoundAndOtherMethodsNeedTheToken) {
  for (const char* target : {"/web/nope.js", "/web/%2e%2e%2frcfd.sqlite", "/web/token", "/web/rcfd.sqlite",
                                    "/web/index.html.bak", "/web/APP.JS"}) {
    const Reply r = anonymous(http::verb::get, target);
    EXPECT_EQ(r.status, 404) << target;
    EXPECT_EQ(r.header("content-type"), "application/problem+json") << target;
  }
  // A path that leaves /web/ is not the page's: without the token 401, with it 400 (no . or .. segments).
  EXPECT_EQ(anonymous(http::verb::get, "/web/../rcfd.sqlite").status, 401);
  EXPECT_EQ(httpRequest(server_->port(), http::verb::get, "/web/../rcfd.sqlite", kToken).status, 400);
  // Only GET of the page's own paths is public: a folder, another method, a deeper path need the token.
  for (const auto& [method, target] : std::vector<std::pair<http::verb, std::string>>{
           {http::verb::get, "/web/"}, {http::verb::get, "/web/x/app.js"}, {http::verb::get, "//"},
           {http::verb::post, "/"}, {http::verb::put, "/web/app.js"}, {http::verb::delete_, "/"},
           {http::verb::get, "/index.html"}, {http::verb::get, "/favicon.ico"}}) {
    const Reply r = anonymous(method, target);
    EXPECT_EQ(r.status, 401) << http::to_string(method) << " " << target << ": " << r.body;
  }
  // With the token, a page path answers only GET.
  const Reply post = httpRequest(server_->port(), http::verb::post, "/", kToken, "{}");
  EXPECT_EQ(post.status, 405);
  EXPECT_EQ(post.header("allow"), "GET");
}

TEST_F(WebPage, NoDataRouteBecamePublic) {
  const std::set<std::string> publicRoutes = {"/v1/health", "/", "/web/{name}"};
  int checked = 0;
  const std::string id(32, 'a');
  for (const auto& route : rcfd::server::routeSpecs()) {
    EXPECT_EQ(!route.authenticated, publicRoutes.count(route.path) == 1) << route.path;
    if (!route.authenticated) continue;
    std::string target = route.path;
    for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{{"{id}", id}, {"{name}", "quick"}})
      if (const auto at = target.find(from); at != std::string::npos) target.replace(at, from.size(), to);
    const Reply r = anonymous(http::string_to_verb(route.method == std::string("post") ? "POST" : "GET"), target);
    EXPECT_EQ(r.status, 401) << route.method << " " << target << ": " << r.body;
    EXPECT_EQ(r.header("content-security-policy"), "") << target;
    ++checked;
  }
  EXPECT_GE(checked, 16);
}

TEST_F(WebPage, TheExamplesAreTheRepositorysScenes) {
  const Reply list = httpRequest(server_->port(), http::verb::get, "/v1/examples", kToken);
  ASSERT_EQ(list.status, 200) << list.body;
  std::set<std::string> names;
  const nlohmann::json examples = list.json();
  for (const auto& e : examples.at("examples")) {
    names.insert(e.at("name").get<std::string>());
    EXPECT_FALSE(e.at("description").get<std::string>().empty()) << e.dump();
  }
  std::set<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(sourceDir() / "examples"))
    if (entry.path().extension() == ".json") files.insert(entry.path().stem().string());
  EXPECT_EQ(names, files);
  const Reply quick = httpRequest(server_->port(), http::verb::get, "/v1/examples/quick", kToken);
  ASSERT_EQ(quick.status, 200);
  EXPECT_EQ(quick.header("content-type"), "application/json");
  std::ifstream in(sourceDir() / "examples" / "quick.json");
  EXPECT_EQ(quick.body, std::string(std::istreambuf_iterator<char>(in), {}));
  const Reply missing = httpRequest(server_->port(), http::verb::get, "/v1/examples/nope", kToken);
  EXPECT_EQ(missing.status, 404);
  EXPECT_NE(missing.json().at("detail").get<std::string>().find("quick"), std::string::npos) << missing.body;
  // A job made from an example as the page makes it is accepted.
  const nlohmann::json job = {{"kind", "database"}, {"scene", quick.json()}, {"seed", 1}};
  EXPECT_EQ(httpRequest(server_->port(), http::verb::post, "/v1/jobs", kToken, job.dump()).status, 202);
}
