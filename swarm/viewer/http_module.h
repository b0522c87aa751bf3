// The seam between swarmsim and its HTTP module (libswarmsim_http.so, built
// from http_server.cc): Debian's cpp-httplib is built with OpenSSL, brotli
// and zlib, so linking it mapped libssl and libcrypto (~3.8 MB resident) into
// every run. server.cc opens the module when a viewer's server is made
// (framework/shared_library.h says where it is looked for); no httplib type
// and no exception crosses the seam. Both sides come from one build
// (kHttpModuleVersion guards a stale module).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace swarmsim::viewer {

// Bumped whenever anything in this file changes.
inline constexpr int kHttpModuleVersion = 1;

// What a server serves (server.h): the page and its script, the recording
// and the other files of `folder` (through FileInside).
struct HttpSite {
  std::filesystem::path folder;
  std::string page;         // ServedPage()
  std::string_view script;  // PageScript(): the program's own bytes, for its life
};

// The server on cpp-httplib.
class HttpServer {
 public:
  virtual ~HttpServer() = default;
  // Binds host:port (0: a free port); the port, or <= 0 when it cannot.
  virtual int Bind(const std::string& host, int port) = 0;
  // Answers requests until Stop().
  virtual void Run() = 0;
  virtual bool running() const = 0;
  virtual void Stop() = 0;
};

// What the module exports, through kHttpModuleEntry.
struct HttpModule {
  int version = 0;  // kHttpModuleVersion of the module's build
  // A new server (the caller deletes it), or null and *error set.
  HttpServer* (*make_server)(const HttpSite& site, std::string* error) = nullptr;
};

// The module's one exported symbol: extern "C" const void* NAME(), the
// module's HttpModule.
inline constexpr const char* kHttpModuleEntry = "swarmsim_http_module";

// The environment variable naming the module's file instead.
inline constexpr const char* kHttpModuleVariable = "SWARMSIM_HTTP_MODULE";

}  // namespace swarmsim::viewer
