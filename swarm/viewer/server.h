// `swarmsim view`'s HTTP server: the page, its script, and the files of one
// output folder the page reads (recording.swrec, read from a byte offset so a
// page follows a run in progress). Nothing outside that folder is served:
// not through `..`, encoded or not, nor absolute paths, nor symbolic links
// that leave it (FileInside). cpp-httplib stays inside server.cc.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <thread>

#include "swarm/viewer/page.h"

namespace swarmsim::viewer {

// The file `request_path` (a URL path below the folder, already
// percent-decoded, without the leading '/') names inside `folder`, resolved
// through symbolic links; nullopt when it is not a regular file inside the
// folder (missing, `..`, absolute, a link leading out).
std::optional<std::filesystem::path> FileInside(const std::filesystem::path& folder,
                                                std::string_view request_path);

class Server {
 public:
  // Serves `folder` (an existing output folder), the page with `options`.
  explicit Server(std::filesystem::path folder, const PageOptions& options = {});
  ~Server();  // stops the server
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Binds host:port (0: a free port) and returns the port; throws Error with
  // a message naming host and port when it cannot (port in use, bad host).
  int Bind(const std::string& host, int port);
  // http://HOST:PORT/ once bound.
  std::string Address() const;
  // Answers requests until Stop(): on this thread (Run) or another (Start).
  void Run();
  void Start();
  void Stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::thread thread_;
};

}  // namespace swarmsim::viewer
