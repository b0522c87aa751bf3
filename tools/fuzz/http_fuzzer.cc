// One HTTP request to the viewer's server (swarm/viewer/server.h), as a
// browser or anything else on the network sends it: the input's bytes are
// sent on a fresh connection to a server on 127.0.0.1 serving an output
// folder, the connection is half-closed, and the answer read to its end.
//
// Beside crashes, two findings: no answer (or no close) within 10 s, and an
// answer that holds the bytes of secret.txt, a file outside the served
// folder that a symbolic link inside it (escape.txt) points to.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>

#include "swarm/viewer/server.h"
#include "tools/fuzz/fuzz_support.h"

namespace {

namespace fs = std::filesystem;

constexpr std::string_view kSecret = "swarmsim-fuzz: this file is outside the served folder";
constexpr int kAnswerTimeoutMs = 10'000;

[[noreturn]] void Finding(const char* what) {
  std::fprintf(stderr, "http fuzzer: %s\n", what);
  std::abort();
}

// The served folder and a server on a free port; never stopped.
int ServerPort() {
  static const int port = [] {
    const fs::path root = swarmsim::fuzz::TempFolder();
    const fs::path site = root / "site";
    fs::create_directories(site / "sub");
    fs::copy_file(swarmsim::fuzz::SourceDir() / "tests/data/recordings/diffusion/recording.swrec",
                  site / "recording.swrec");
    swarmsim::fuzz::WriteFile(site / "summary.json", R"({"status": "ok", "steps": 30})");
    swarmsim::fuzz::WriteFile(site / "sub" / "notes.txt", "notes\n");
    swarmsim::fuzz::WriteFile(root / "secret.txt", kSecret);
    fs::create_symlink(root / "secret.txt", site / "escape.txt");
    fs::create_symlink("..", site / "up");
    auto* server = new swarmsim::viewer::Server(site);  // runs until exit
    const int bound = server->Bind("127.0.0.1", 0);
    server->Start();
    return bound;
  }();
  return port;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const int port = ServerPort();
  const int sock = socket(AF_INET, SOCK_STREAM, 0);
  if (sock < 0) Finding("cannot make a socket");
  // Closed with a reset: no TIME_WAIT left behind per input.
  const linger reset{1, 0};
  setsockopt(sock, SOL_SOCKET, SO_LINGER, &reset, sizeof(reset));
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  // The server may be starting on its thread: try for a while.
  int connected = -1;
  for (int attempt = 0; attempt < 200 && connected != 0; ++attempt) {
    connected = connect(sock, reinterpret_cast<const sockaddr*>(&address), sizeof(address));
    if (connected != 0) usleep(10'000);
  }
  if (connected != 0) Finding("cannot connect to the server");
  // The request; the server may answer and close before it has all of it.
  for (size_t sent = 0; sent < size;) {
    const ssize_t n = send(sock, data + sent, size - sent, MSG_NOSIGNAL);
    if (n <= 0) break;
    sent += static_cast<size_t>(n);
  }
  shutdown(sock, SHUT_WR);
  // The answer, to the server's close.
  std::string answer;
  char buffer[1 << 16];
  for (;;) {
    pollfd wait{sock, POLLIN, 0};
    const int ready = poll(&wait, 1, kAnswerTimeoutMs);
    if (ready == 0) Finding("no answer, or the connection left open, 10 s after the request");
    if (ready < 0) break;
    const ssize_t n = recv(sock, buffer, sizeof(buffer), 0);
    if (n <= 0) break;
    answer.append(buffer, static_cast<size_t>(n));
  }
  close(sock);
  if (answer.find(kSecret) != std::string::npos)
    Finding("the answer holds secret.txt, a file outside the served folder");
  return 0;
}
