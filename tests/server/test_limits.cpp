// rcfd-server under connection pressure, on loopback: descriptors used up (a low RLIMIT_NOFILE), the
// per-peer cap, and connections that never send a token.

#include <gtest/gtest.h>
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>

#include <fstream>
#include <sstream>

#include "../SanitizedBuild.hpp"
#include "ServerFixture.hpp"

using namespace rcfd::test;
namespace http = boost::beast::http;

namespace {

/// A TCP connection to the server that sends nothing.
int idleConnection(unsigned short port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(port);
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (fd < 0 || ::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) throw std::runtime_error("connect");
  return fd;
}

/// Whether the server closed the connection (end of stream or reset) within `seconds`.
bool closedByServerWithin(int fd, double seconds) {
  pollfd p{fd, POLLIN, 0};
  if (::poll(&p, 1, int(seconds * 1000)) <= 0) return false;
  char c;
  return ::recv(fd, &c, 1, MSG_DONTWAIT) <= 0;
}

/// CPU seconds (user + system) the process has used.
double cpuSeconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string stat((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::istringstream fields(stat.substr(stat.rfind(')') + 2));
  std::string f;
  double ticks = 0.0;
  for (int i = 3; i <= 15 && fields >> f; ++i)
    if (i == 14 || i == 15) ticks += std::stod(f);
  return ticks / double(::sysconf(_SC_CLK_TCK));
}

long linesContaining(const std::string& text, const std::string& what) {
  long n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

bool healthAnswersWithin(unsigned short port, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    try {
      if (httpRequest(port, http::verb::get, "/v1/health").status == 200) return true;
    } catch (const std::exception&) {
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return false;
}

}  // namespace

TEST(ServerLimits, DescriptorsUsedUpNeitherSpinNorFloodTheLogAndTheServerRecovers) {
  // The sanitizers' runtime tests whether memory is readable by writing it into a pipe: with every
  // descriptor taken, UBSan's vptr check of Boost's error categories cannot, and reports an invalid
  // vptr where there is none.
  if (rcfd::test::kSanitizedBuild)
    GTEST_SKIP() << "a sanitizer runtime needs free descriptors of its own (docs/stability.md, \"Sanitizers\")";
  TempDir dir;
  ServerProcess server(dir.path() / "data", "limits-token",
                       {"--workers", "0", "--idle-before-token", "2", "--max-connections", "1000",
                        "--max-connections-per-peer", "1000"},
                       /*fileLimit=*/48);
  std::vector<int> held;
  for (int i = 0; i < 120; ++i) held.push_back(idleConnection(server.port()));  // the backlog takes them
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const double cpu0 = cpuSeconds(server.pid());
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const double cpu = cpuSeconds(server.pid()) - cpu0;
  EXPECT_LT(cpu, 0.5) << "a server retrying accept at once spins a core";
  const std::string log = server.stderrText();
  EXPECT_GE(linesContaining(log, "accept:"), 1) << "the descriptors did not run out: the test proves nothing";
  EXPECT_LE(linesContaining(log, "accept:"), 3) << log.substr(0, 2000);
  for (const int fd : held) ::close(fd);
  EXPECT_TRUE(healthAnswersWithin(server.port(), 10.0)) << server.stderrText().substr(0, 4000);
  EXPECT_TRUE(server.alive());
}

TEST(ServerLimits, ConnectionsBeyondThePerPeerCapAreClosedAtOnce) {
  TempDir dir;
  ServerProcess server(dir.path() / "data", "limits-token", {"--workers", "0", "--max-connections-per-peer", "3"});
  std::vector<int> held;
  for (int i = 0; i < 3; ++i) held.push_back(idleConnection(server.port()));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const int fourth = idleConnection(server.port());
  EXPECT_TRUE(closedByServerWithin(fourth, 2.0));
  for (const int fd : held) EXPECT_FALSE(closedByServerWithin(fd, 0.05));
  ::close(fourth);
  ::close(held.back());
  held.pop_back();
  EXPECT_TRUE(healthAnswersWithin(server.port(), 5.0));
  for (const int fd : held) ::close(fd);
}

TEST(ServerLimits, AConnectionThatSendsNoTokenIsClosedAfterTheShortIdleTime) {
  TempDir dir;
  ServerProcess server(dir.path() / "data", "limits-token", {"--workers", "0", "--idle-before-token", "1"});
  const int idle = idleConnection(server.port());
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_TRUE(closedByServerWithin(idle, 5.0));
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_GT(waited, 0.8);
  EXPECT_LT(waited, 3.0);
  ::close(idle);
}
