// swarmsim view's server: it serves the page and the files of its folder,
// and nothing outside the folder however the path is written; hostile
// requests get an HTTP error and the server goes on answering.
#include "swarm/viewer/server.h"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "tests/swarm/run_program.h"

namespace swarmsim::viewer {
namespace {
namespace fs = std::filesystem;
using swarmsim::testing::FreshTempDir;
using swarmsim::testing::RunProgram;

// A run folder `run` with a recording and a sub-folder, beside a secret
// file and folder it must not expose, and links leading in and out.
class ServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = FreshTempDir("viewer_server",
                         ::testing::UnitTest::GetInstance()->current_test_info()->name());
    run_ = root_ / "run";
    fs::create_directories(run_ / "meshes");
    std::ofstream(run_ / "recording.swrec") << "RECORDING";
    std::ofstream(run_ / "meshes" / "part.stl") << "MESH";
    std::ofstream(root_ / "secret.txt") << "SECRET";
    fs::create_directories(root_ / "run-other");
    std::ofstream(root_ / "run-other" / "x.txt") << "SECRET2";
    fs::create_symlink(root_ / "secret.txt", run_ / "out_link.txt");
    fs::create_symlink("../secret.txt", run_ / "out_link_relative.txt");
    fs::create_symlink(root_, run_ / "up");
    fs::create_symlink(run_ / "meshes" / "part.stl", run_ / "in_link.stl");
  }
  void TearDown() override { fs::remove_all(root_); }

  fs::path root_, run_;
};

TEST_F(ServerTest, FileInsideAcceptsTheFolderFilesOnly) {
  EXPECT_EQ(FileInside(run_, "recording.swrec"), fs::canonical(run_ / "recording.swrec"));
  EXPECT_EQ(FileInside(run_, "meshes/part.stl"), fs::canonical(run_ / "meshes/part.stl"));
  EXPECT_EQ(FileInside(run_, "in_link.stl"), fs::canonical(run_ / "meshes/part.stl"));
  for (const char* outside :
       {"../secret.txt", "meshes/../../secret.txt", "/etc/passwd", "out_link.txt",
        "out_link_relative.txt", "up/secret.txt", "../run-other/x.txt", "meshes", ".", "",
        "./recording.swrec", "missing.txt"})
    EXPECT_FALSE(FileInside(run_, outside)) << outside;
}

// One raw exchange with 127.0.0.1:port: what came back. `hang_up`: close
// our side after sending (the server sees the end of a broken request
// instead of waiting for more).
std::string Exchange(int port, const std::string& request, bool hang_up = false) {
  const int sock = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(port);
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::string answer;
  if (::connect(sock, reinterpret_cast<sockaddr*>(&address), sizeof(address)) == 0) {
    timeval timeout{2, 0};
    ::setsockopt(sock, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
    ::send(sock, request.data(), request.size(), MSG_NOSIGNAL);
    if (hang_up) ::shutdown(sock, SHUT_WR);
    char buffer[4096];
    ssize_t n;
    while ((n = ::recv(sock, buffer, sizeof(buffer), 0)) > 0) answer.append(buffer, n);
  }
  ::close(sock);
  return answer;
}

std::string Get(int port, const std::string& target) {
  return Exchange(port, "GET " + target + " HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
}

TEST_F(ServerTest, ServesThePageAndFolderFilesButNothingOutside) {
  Server server(run_);
  const int port = server.Bind("127.0.0.1", 0);
  server.Start();
  EXPECT_NE(Get(port, "/").find("<canvas id=\"plot\">"), std::string::npos);
  EXPECT_NE(Get(port, "/viewer.js").find("200 OK"), std::string::npos);
  EXPECT_NE(Get(port, "/recording.swrec").find("\r\n\r\nRECORDING"), std::string::npos);
  EXPECT_NE(Get(port, "/recording.swrec?from=3").find("\r\n\r\nORDING"), std::string::npos);
  EXPECT_NE(Get(port, "/recording.swrec?from=x").find("400"), std::string::npos);
  EXPECT_NE(Get(port, "/files/meshes/part.stl").find("MESH"), std::string::npos);
  // Every way out of the folder: an error, never the secret.
  for (const char* target :
       {"/files/../secret.txt", "/files/%2e%2e/secret.txt", "/files/%2E%2E%2Fsecret.txt",
        "/files/meshes/..%2f..%2fsecret.txt", "/files/%252e%252e/secret.txt", "/files//etc/passwd",
        "/files/%2fetc%2fpasswd", "/files/out_link.txt", "/files/out_link_relative.txt",
        "/files/up/secret.txt", "/files/up/run-other/x.txt", "/../secret.txt", "/%2e%2e/secret.txt",
        "/files/..\\secret.txt", "/files/%00secret.txt", "/files/recording.swrec%00.txt",
        "/etc/passwd", "/files/", "/files"}) {
    const std::string answer = Get(port, target);
    EXPECT_EQ(answer.find("SECRET"), std::string::npos) << target;
    EXPECT_EQ(answer.find("root:"), std::string::npos) << target;
    EXPECT_TRUE(answer.empty() || answer.find(" 200 ") == std::string::npos) << target << answer;
  }
}

TEST_F(ServerTest, SurvivesHostileRequestsAndGoesOnAnswering) {
  Server server(run_);
  const int port = server.Bind("127.0.0.1", 0);
  server.Start();
  std::mt19937 random(7);
  std::vector<std::string> requests = {
      "",
      "\r\n\r\n",
      "GET\r\n\r\n",
      "GET / HTTP/9.9\r\n\r\n",
      "BREW /coffee HTTP/1.1\r\n\r\n",
      "GET /" + std::string(100000, 'a') + " HTTP/1.1\r\n\r\n",
      "GET / HTTP/1.1\r\nHost: x\r\n" + std::string(200000, 'h') + "\r\n\r\n",
      "POST / HTTP/1.1\r\nContent-Length: 99999999999\r\n\r\nabc",
      "POST / HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\nzz\r\n",
      "GET /recording.swrec?from=99999999999999999999999 HTTP/1.1\r\n\r\n",
      "GET /recording.swrec?from=-1 HTTP/1.1\r\n\r\n",
      "GET /files/%ZZ%ZZ HTTP/1.1\r\n\r\n",
      "GET /%c0%ae%c0%ae/secret.txt HTTP/1.1\r\n\r\n",
      "GET /recording.swrec HTTP/1.1\r\nRange: bytes=5-2,999999999-\r\n\r\n"};
  for (int i = 0; i < 200; ++i) {
    std::string junk(random() % 600, '\0');
    for (char& c : junk) c = static_cast<char>(random() % 256);
    requests.push_back(i % 2 ? junk : "GET /" + junk + " HTTP/1.1\r\n\r\n");
  }
  for (const std::string& request : requests) {
    const std::string answer = Exchange(port, request, /*hang_up=*/true);
    EXPECT_EQ(answer.find("SECRET"), std::string::npos);
  }
  EXPECT_NE(Get(port, "/recording.swrec").find("\r\n\r\nRECORDING"), std::string::npos);
}

// The Content-Length header of an answer, -1 without one.
long long ContentLength(const std::string& answer) {
  const size_t at = answer.find("Content-Length: ");
  if (at == std::string::npos) return -1;
  return std::stoll(answer.substr(at + 16, answer.find("\r\n", at) - at - 16));
}

// The body of an answer: what follows the headers.
std::string Body(const std::string& answer) {
  const size_t at = answer.find("\r\n\r\n");
  return at == std::string::npos ? "" : answer.substr(at + 4);
}

std::string GetRange(int port, const std::string& target, const std::string& range) {
  return Exchange(port, "GET " + target + " HTTP/1.1\r\nHost: x\r\nRange: " + range +
                            "\r\nConnection: close\r\n\r\n");
}

// A range past the end is refused (416), an end past the file is clamped:
// never a length the body does not have.
TEST_F(ServerTest, RangesPastTheEndAreRefusedOrClamped) {
  Server server(run_);
  const int port = server.Bind("127.0.0.1", 0);
  server.Start();
  for (const char* target : {"/recording.swrec", "/files/recording.swrec"}) {
    const std::string past = GetRange(port, target, "bytes=999999999-");
    EXPECT_NE(past.find(" 416 "), std::string::npos) << target << past;
    EXPECT_NE(past.find("Content-Range: bytes */9"), std::string::npos) << past;
    EXPECT_EQ(ContentLength(past), static_cast<long long>(Body(past).size())) << past;

    const std::string clamped = GetRange(port, target, "bytes=3-999999999999");
    EXPECT_NE(clamped.find(" 206 "), std::string::npos) << target << clamped;
    EXPECT_NE(clamped.find("Content-Range: bytes 3-8/9"), std::string::npos) << clamped;
    EXPECT_EQ(ContentLength(clamped), 6) << clamped;
    EXPECT_EQ(Body(clamped), "ORDING");

    const std::string middle = GetRange(port, target, "bytes=2-4");
    EXPECT_NE(middle.find(" 206 "), std::string::npos) << middle;
    EXPECT_EQ(Body(middle), "COR");
    EXPECT_EQ(Body(GetRange(port, target, "bytes=-3")), "ING");
  }
  // The page's own question (?from=) combines with a range over what is left.
  EXPECT_EQ(Body(GetRange(port, "/recording.swrec?from=3", "bytes=1-2")), "RD");
}

// A file larger than one recording answer (64 MiB) comes whole from
// /files/, never a 200 with a cut body.
TEST_F(ServerTest, LargeFilesAreServedWhole) {
  const uintmax_t size = (64ull << 20) + 12345;
  std::ofstream(run_ / "big.bin").close();
  fs::resize_file(run_ / "big.bin", size);
  Server server(run_);
  const int port = server.Bind("127.0.0.1", 0);
  server.Start();
  const std::string answer = Get(port, "/files/big.bin");
  ASSERT_NE(answer.find(" 200 "), std::string::npos) << answer.substr(0, 200);
  EXPECT_EQ(ContentLength(answer), static_cast<long long>(size));
  EXPECT_EQ(Body(answer).size(), size);
}

TEST_F(ServerTest, ProgramSaysWhenThePortIsInUseOrTheFolderHasNoRecording) {
  // A real recording, so only the port stands in the way.
  fs::copy_file(
      std::string(SWARMSIM_SOURCE_DIR) + "/tests/data/recordings/diffusion/recording.swrec",
      run_ / "recording.swrec", fs::copy_options::overwrite_existing);
  Server server(run_);
  const int port = server.Bind("127.0.0.1", 0);
  const auto taken = RunProgram("view " + run_.string() + " --port " + std::to_string(port));
  EXPECT_EQ(taken.exit_code, 1) << taken.output;
  EXPECT_NE(taken.output.find("cannot listen on 127.0.0.1:" + std::to_string(port)),
            std::string::npos)
      << taken.output;
  // An address that is none is said so (it was "the port is in use").
  const auto no_address = RunProgram("view " + run_.string() + " --host 999.1.1.1 --port 0");
  EXPECT_EQ(no_address.exit_code, 1) << no_address.output;
  EXPECT_NE(no_address.output.find("'999.1.1.1' is no address or host name"), std::string::npos)
      << no_address.output;
  const auto empty = RunProgram("view " + (root_ / "run-other").string());
  EXPECT_EQ(empty.exit_code, 2) << empty.output;
  EXPECT_NE(empty.output.find("has no recording.swrec: record a run with swarmsim run WORLD --out"),
            std::string::npos)
      << empty.output;
  const auto missing = RunProgram("view " + (root_ / "nowhere").string());
  EXPECT_EQ(missing.exit_code, 2) << missing.output;
  EXPECT_NE(missing.output.find("is not a folder"), std::string::npos) << missing.output;
}

}  // namespace
}  // namespace swarmsim::viewer
