// Native TLS (--tls-cert/--tls-key) against a real rcfd-server on loopback, with a self-signed
// certificate made for the test: the API over HTTPS (401 before a large body included), nothing over
// plain HTTP on that port; the `rcfd` client over https:// with the CA given by --cacert or
// RCFD_CACERT (submit, status, upload, download), refusing an untrusted certificate or one for another
// name, and saying so when an https:// URL meets a plain server; a certificate or key that cannot be
// used stops the server at start.

#include <gtest/gtest.h>

#include "ClientRunner.hpp"
#include "ServerFixture.hpp"
#include "SmallDatabase.hpp"
#include "TlsFixture.hpp"

using namespace rcfd::test;
namespace http = boost::beast::http;

namespace {

constexpr const char* kToken = "tls-token-4b1e";

std::vector<std::string> tlsArgs(const Certificate& c) {
  return {"--workers", "0", "--tls-cert", c.cert.string(), "--tls-key", c.key.string()};
}

class Tls : public ::testing::Test {
 protected:
  void SetUp() override {
    tmp_ = std::make_unique<TempDir>();
    cert_ = selfSignedCertificate(tmp_->path() / "tls");
    server_ = std::make_unique<ServerProcess>(tmp_->path() / "data", kToken, tlsArgs(cert_));
  }
  Reply https(http::verb method, const std::string& target, const std::string& token = kToken,
              const std::string& body = {}) const {
    return httpsRequest(server_->port(), cert_.cert, method, target, token, body);
  }
  /// The client's arguments for this server, CA by flag.
  std::vector<std::string> client(std::vector<std::string> args) const {
    args.insert(args.begin(), {"--server", server_->url(), "--cacert", cert_.cert.string(), "--token", kToken});
    return args;
  }
  std::unique_ptr<TempDir> tmp_;
  Certificate cert_;
  std::unique_ptr<ServerProcess> server_;
};

TEST_F(Tls, ServesTheApiOverHttpsAndNothingOverPlainHttp) {
  EXPECT_EQ(server_->firstLine(), "listening on https://127.0.0.1:" + std::to_string(server_->port()));
  EXPECT_EQ(https(http::verb::get, "/v1/health", "").status, 200);
  const auto submitted = https(http::verb::post, "/v1/jobs", kToken, databaseJob(1).dump());
  ASSERT_EQ(submitted.status, 202) << submitted.body;
  const std::string id = submitted.json().at("id");
  EXPECT_EQ(https(http::verb::get, "/v1/jobs/" + id).json().at("owner"), "admin");
  EXPECT_EQ(https(http::verb::get, "/v1/jobs").json().at("jobs").size(), 1u);
  // Without the token: 401 from the header, before a body over the limit is judged, and the TLS
  // connection closed cleanly after it.
  const auto anonymous = https(http::verb::post, "/v1/jobs", "", std::string(2u << 20, ' '));
  EXPECT_EQ(anonymous.status, 401) << anonymous.body;
  EXPECT_EQ(anonymous.header("www-authenticate"), "Bearer realm=\"rcfd\"");
  EXPECT_EQ(https(http::verb::post, "/v1/jobs", kToken, std::string(2u << 20, ' ')).status, 413);
  // Plain HTTP on the HTTPS port gets no answer at all; the server goes on serving HTTPS.
  EXPECT_THROW(httpRequest(server_->port(), http::verb::get, "/v1/health"), std::runtime_error);
  EXPECT_THROW(httpRequest(server_->port(), http::verb::get, "/v1/jobs", kToken), std::runtime_error);
  EXPECT_EQ(https(http::verb::get, "/v1/health", "").status, 200);
}

TEST_F(Tls, TheClientTalksHttpsWithTheServersCertificateAuthority) {
  std::ofstream(tmp_->path() / "job.json") << databaseJob(2).dump();
  const auto submitted = runClient(client({"submit", (tmp_->path() / "job.json").string()}));
  ASSERT_EQ(submitted.code, 0) << submitted.err;
  const std::string id = firstLine(submitted.out);
  // The CA from the environment instead of the flag.
  const auto status = runClient({"status", id},
                                {"RCFD_SERVER=" + server_->url(), "RCFD_TOKEN=" + std::string(kToken),
                                 "RCFD_CACERT=" + cert_.cert.string()});
  EXPECT_EQ(status.code, 0) << status.err;
  EXPECT_NE(status.out.find("state:     QUEUED"), std::string::npos) << status.out;
  EXPECT_EQ(runClient(client({"jobs"})).code, 0);
  // A file streamed each way: an upload (validated by the server) and an artifact download.
  writeSmallDatabase(quickScene(), tmp_->path() / "db.h5");
  const auto uploaded = runClient(client({"upload", (tmp_->path() / "db.h5").string()}));
  EXPECT_EQ(uploaded.code, 0) << uploaded.err;
  EXPECT_EQ(firstLine(uploaded.out).size(), 32u) << uploaded.out;
  std::filesystem::create_directories(tmp_->path() / "data" / "jobs" / id);
  const std::string log(100000, 'x');
  std::ofstream(tmp_->path() / "data" / "jobs" / id / "solver.log") << log;
  const auto out = tmp_->path() / "solver.log";
  const auto downloaded = runClient(client({"download", id, "solver.log", "-o", out.string()}));
  ASSERT_EQ(downloaded.code, 0) << downloaded.err;
  std::ifstream in(out);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), log);
  // A 404 over TLS is an answer like any other.
  const auto missing = runClient(client({"status", "00000000000000000000000000000000"}));
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.err.find("HTTP 404"), std::string::npos) << missing.err;
}

TEST_F(Tls, TheClientRefusesAnUntrustedCertificateAndPlainHttpToTheHttpsPort) {
  // The system's CAs do not know the self-signed certificate.
  const auto untrusted = runClient({"--server", server_->url(), "--token", kToken, "jobs"});
  EXPECT_EQ(untrusted.code, 1);
  EXPECT_NE(untrusted.err.find("certificate is not trusted"), std::string::npos) << untrusted.err;
  EXPECT_NE(untrusted.err.find("--cacert"), std::string::npos) << untrusted.err;
  const std::string plainUrl = "http://127.0.0.1:" + std::to_string(server_->port());
  const auto plain = runClient({"--server", plainUrl, "--token", kToken, "--timeout", "5", "jobs"});
  EXPECT_EQ(plain.code, 1) << plain.err;
  EXPECT_NE(plain.err.find("use an https:// URL"), std::string::npos) << plain.err;
  // A CA file is for https:// only, and must be one.
  EXPECT_EQ(runClient({"--server", plainUrl, "--cacert", cert_.cert.string(), "jobs"}).code, 2);
  EXPECT_EQ(runClient({"--server", server_->url(), "--cacert", (tmp_->path() / "none.pem").string(), "jobs"}).code, 2);
}

TEST(TlsNames, TheClientRefusesACertificateForAnotherName) {
  TempDir tmp;
  const auto elsewhere = selfSignedCertificate(tmp.path() / "tls", "DNS:rcfd.elsewhere.example");
  ServerProcess server(tmp.path() / "data", kToken, tlsArgs(elsewhere));
  const auto r = runClient({"--server", server.url(), "--cacert", elsewhere.cert.string(), "--token", kToken, "jobs"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("IP address mismatch"), std::string::npos) << r.err;
  EXPECT_THROW(httpsRequest(server.port(), elsewhere.cert, http::verb::get, "/v1/health"), std::runtime_error);
}

TEST(TlsNames, AnHttpsUrlForAPlainServerSaysWhatIsWrong) {
  TempDir tmp;
  const auto cert = selfSignedCertificate(tmp.path() / "tls");
  ServerProcess plain(tmp.path() / "data", kToken);
  const std::string url = "https://127.0.0.1:" + std::to_string(plain.port());
  const auto r = runClient({"--server", url, "--cacert", cert.cert.string(), "--token", kToken, "jobs"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("does the server speak HTTPS?"), std::string::npos) << r.err;
}

TEST(TlsStart, ACertificateOrKeyThatCannotBeUsedStopsTheServer) {
  TempDir tmp;
  const auto good = selfSignedCertificate(tmp.path() / "a");
  const auto other = selfSignedCertificate(tmp.path() / "b");
  const auto notPem = tmp.path() / "not.pem";
  std::ofstream(notPem) << "not a certificate\n";
  const auto startError = [&](std::vector<std::string> args) {
    try {
      ServerProcess server(tmp.path() / "data", kToken, args);
      return std::string();
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
  };
  const auto garbage = startError({"--tls-cert", notPem.string(), "--tls-key", good.key.string()});
  EXPECT_NE(garbage.find("--tls-cert " + notPem.string() + ": not a PEM certificate chain"), std::string::npos)
      << garbage;
  const auto mismatch = startError({"--tls-cert", good.cert.string(), "--tls-key", other.key.string()});
  EXPECT_NE(mismatch.find("is not the key of --tls-cert"), std::string::npos) << mismatch;
  const auto absent = startError({"--tls-cert", good.cert.string(), "--tls-key", (tmp.path() / "none").string()});
  EXPECT_NE(absent.find("--tls-key"), std::string::npos) << absent;
  const auto alone = startError({"--tls-cert", good.cert.string()});
  EXPECT_NE(alone.find("--tls-key"), std::string::npos) << alone;  // the one needs the other
}

}  // namespace
