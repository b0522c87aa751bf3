// swarmsim view's server with clients that hold connections open or send
// broken requests, as a colleague's browser tabs and a hostile client do:
// every other request is still answered at once (issue 26).
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "swarm/viewer/server.h"
#include "tests/swarm/run_program.h"

namespace swarmsim::viewer {
namespace {
namespace fs = std::filesystem;
using swarmsim::testing::FreshTempDir;

// A TCP connection to 127.0.0.1:port whose reads give up after `timeout_s`.
int Connect(int port, int timeout_s = 2) {
  const int sock = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(port);
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(sock, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
    ::close(sock);
    return -1;
  }
  timeval timeout{timeout_s, 0};
  ::setsockopt(sock, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
  return sock;
}

// What came back on `sock` until the server closed it (`closed`) or the
// read timed out.
struct Answer {
  std::string bytes;
  bool closed = false;
};
Answer ReadUntilClosed(int sock) {
  Answer answer;
  char buffer[4096];
  ssize_t n;
  while ((n = ::recv(sock, buffer, sizeof(buffer), 0)) > 0) answer.bytes.append(buffer, n);
  answer.closed = n == 0;
  return answer;
}

// `request` sent on a new connection (left open on our side, as a stuck
// client leaves it), read for at most `timeout_s`.
Answer Exchange(int port, const std::string& request, int timeout_s) {
  const int sock = Connect(port, timeout_s);
  if (sock < 0) return {};
  ::send(sock, request.data(), request.size(), MSG_NOSIGNAL);
  Answer answer = ReadUntilClosed(sock);
  ::close(sock);
  return answer;
}

class ServerConnectionsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    run_ = FreshTempDir("viewer_connections",
                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(run_);
    std::ofstream(run_ / "recording.swrec") << "RECORDING";
  }
  void TearDown() override { fs::remove_all(run_); }
  fs::path run_;
};

TEST_F(ServerConnectionsTest, AHundredIdleConnectionsDoNotHoldUpARequest) {
  Server server(run_);
  const int port = server.Bind("127.0.0.1", 0);
  server.Start();
  // 50 connections that never send a thing, 50 kept alive after a request,
  // as browser tabs leave them.
  std::vector<int> idle;
  for (int i = 0; i < 50; ++i) idle.push_back(Connect(port));
  for (int i = 0; i < 50; ++i) {
    const int sock = Connect(port);
    const std::string request = "GET /favicon.ico HTTP/1.1\r\nHost: x\r\n\r\n";
    ::send(sock, request.data(), request.size(), MSG_NOSIGNAL);
    char buffer[1024];
    EXPECT_GT(::recv(sock, buffer, sizeof(buffer), 0), 0) << "keep-alive request " << i;
    idle.push_back(sock);
  }
  for (const int sock : idle) ASSERT_GE(sock, 0);
  // The next request is answered within the 2 s the client waits (it took
  // a minute when 8 idle connections held httplib's 8 threads).
  for (const char* target : {"/recording.swrec", "/", "/viewer.js"}) {
    const Answer answer = Exchange(
        port, std::string("GET ") + target + " HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n",
        2);
    EXPECT_EQ(answer.bytes.rfind("HTTP/1.1 200 OK", 0), 0u) << target << ": " << answer.bytes;
    EXPECT_TRUE(answer.closed) << target;
  }
  EXPECT_NE(
      Exchange(port, "GET /recording.swrec HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n", 2)
          .bytes.find("\r\n\r\nRECORDING"),
      std::string::npos);
  for (const int sock : idle) ::close(sock);
}

TEST_F(ServerConnectionsTest, ABrokenRequestIsAnsweredAndClosedPromptly) {
  Server server(run_);
  const int port = server.Bind("127.0.0.1", 0);
  server.Start();
  // Whole but malformed: a 400 at once, and the connection closed within
  // the 3 s the client waits (it stayed open 5 s).
  for (const std::string& request :
       std::vector<std::string>{"BREW\r\n\r\n", "GET / HTTP/1.1\nHost: x\n\n",
                                "\x01\x02\xff junk\r\n\r\n", "GET / HTTP/9.9 extra\r\n\r\n"}) {
    const Answer answer = Exchange(port, request, 3);
    EXPECT_EQ(answer.bytes.rfind("HTTP/1.1 400", 0), 0u) << request << ": " << answer.bytes;
    EXPECT_TRUE(answer.closed) << request;
  }
  // Stopped halfway: a 400, or the connection closed, within the 3 s (it
  // took 5 s).
  for (const std::string& request :
       std::vector<std::string>{"GET / HTTP/1.1\r\nHost: x\r\n", "GET /recording.swr", "G"}) {
    const Answer answer = Exchange(port, request, 3);
    EXPECT_TRUE(answer.bytes.rfind("HTTP/1.1 400", 0) == 0 ||
                (answer.bytes.empty() && answer.closed))
        << request << ": " << answer.bytes << (answer.closed ? " (closed)" : " (still open)");
  }
  // And the server goes on answering.
  EXPECT_NE(
      Exchange(port, "GET /recording.swrec HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n", 2)
          .bytes.find("\r\n\r\nRECORDING"),
      std::string::npos);
}

TEST_F(ServerConnectionsTest, ALargeRecordingIsServedWholeFromAnyOffset) {
  // Larger than the pieces an answer is read in, of bytes that differ.
  std::string bytes(300000, '\0');
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<char>((i * 7919) % 251);
  std::ofstream(run_ / "recording.swrec", std::ios::binary) << bytes;
  Server server(run_);
  const int port = server.Bind("127.0.0.1", 0);
  server.Start();
  for (const size_t from : {size_t{0}, size_t{1}, size_t{65536}, size_t{299999}, size_t{300000}}) {
    const Answer answer = Exchange(port,
                                   "GET /recording.swrec?from=" + std::to_string(from) +
                                       " HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n",
                                   5);
    const size_t body = answer.bytes.find("\r\n\r\n");
    ASSERT_NE(body, std::string::npos) << from;
    EXPECT_NE(answer.bytes.find("X-Swarmsim-Size: 300000\r\n"), std::string::npos) << from;
    EXPECT_TRUE(answer.bytes.substr(body + 4) == bytes.substr(from))
        << "from " << from << ": " << answer.bytes.size() - body - 4 << " bytes";
  }
}

}  // namespace
}  // namespace swarmsim::viewer
