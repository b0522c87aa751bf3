// The HTTP server of `swarmsim view`: the HTTP module's server
// (http_module.h, http_server.cc on cpp-httplib), opened on first use so
// that a run without a viewer maps neither cpp-httplib nor the OpenSSL it
// is built with.
#include "swarm/viewer/server.h"

#include <netdb.h>
#include <sys/socket.h>

#include <chrono>
#include <string>
#include <thread>

#include "framework/error.h"
#include "framework/shared_library.h"
#include "framework/start_thread.h"
#include "swarm/viewer/assets.h"
#include "swarm/viewer/http_module.h"
#include "swarm/viewer/page.h"

namespace swarmsim::viewer {
namespace fs = std::filesystem;

namespace {

// Set by swarm/viewer/CMakeLists.txt: the module's file name and where this
// build put it.
#ifndef SWARMSIM_HTTP_MODULE_NAME
#define SWARMSIM_HTTP_MODULE_NAME "libswarmsim_http.so"
#endif
#ifndef SWARMSIM_HTTP_MODULE_PATH
#define SWARMSIM_HTTP_MODULE_PATH ""
#endif

// The module, once per process: a failure is kept and thrown again.
const HttpModule& Http() {
  static const LazyOwnLibrary library(
      OwnLibrary{SWARMSIM_HTTP_MODULE_NAME, SWARMSIM_HTTP_MODULE_PATH, kHttpModuleVariable,
                 kHttpModuleEntry, kHttpModuleVersion,
                 "the viewer's server needs swarmsim's HTTP module (" SWARMSIM_HTTP_MODULE_NAME
                 ", on cpp-httplib: Debian's libcpp-httplib0.11, which tools/setup.sh installs)"});
  return *static_cast<const HttpModule*>(library.Get());
}

}  // namespace

struct Server::Impl {
  std::unique_ptr<HttpServer> http;
  std::string host;
  int port = 0;
};

Server::Server(fs::path folder, const PageOptions& options) : impl_(std::make_unique<Impl>()) {
  std::string error;
  impl_->http.reset(
      Http().make_server(HttpSite{std::move(folder), ServedPage(options), PageScript()}, &error));
  if (impl_->http == nullptr) throw Error("the viewer's server: " + error);
}

Server::~Server() { Stop(); }

int Server::Bind(const std::string& host, int port) {
  const int bound = impl_->http->Bind(host, port);
  if (bound <= 0) {
    // A host that is no address at all (999.1.1.1, a misspelt name) is said
    // so, not taken for a port in use.
    addrinfo hints{};
    hints.ai_socktype = SOCK_STREAM;
    addrinfo* found = nullptr;
    const int gai = ::getaddrinfo(host.c_str(), nullptr, &hints, &found);
    if (found != nullptr) ::freeaddrinfo(found);
    if (gai != 0)
      throw Error("cannot listen on " + host + ": '" + host + "' is no address or host name (" +
                  ::gai_strerror(gai) +
                  "); --host takes an address of this machine's, such as "
                  "127.0.0.1 or 0.0.0.0");
    throw Error("cannot listen on " + host + ":" + (port > 0 ? std::to_string(port) : "0") +
                ": the port is in use or the address is not this machine's (--port 0 picks a "
                "free port)");
  }
  impl_->host = host;
  impl_->port = bound;
  return bound;
}

std::string Server::Address() const {
  const bool ipv6 = impl_->host.find(':') != std::string::npos;
  return "http://" + (ipv6 ? "[" + impl_->host + "]" : impl_->host) + ":" +
         std::to_string(impl_->port) + "/";
}

void Server::Run() { impl_->http->Run(); }

void Server::Start() {
  thread_ = StartThread("the viewer's server", [this] { Run(); });
}

void Server::Stop() {
  // A server started on another thread may not be listening yet.
  for (int i = 0; thread_.joinable() && !impl_->http->running() && i < 2000; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  impl_->http->Stop();
  if (thread_.joinable()) thread_.join();
}

}  // namespace swarmsim::viewer
