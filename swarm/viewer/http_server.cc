// The HTTP server of `swarmsim view` on cpp-httplib, inside the HTTP module
// (http_module.h): the page, its script, the recording from a byte offset,
// and other files of the output folder, behind Server (server.h).
#include <httplib.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <system_error>
#include <thread>

#include "framework/regular_file.h"
#include "swarm/viewer/http_module.h"
#include "swarm/viewer/page.h"
#include "swarm/viewer/server.h"

namespace swarmsim::viewer {
namespace fs = std::filesystem;

namespace {

// At most this many bytes in one answer for the recording: a page reading a
// larger file asks again from where the answer ended.
constexpr uint64_t kMaxRecordingAnswer = 64ull << 20;
// An answer's bytes are read from the file in pieces of this size as they
// are sent, so a connection holds no more of them (kMaxConnections at once).
constexpr size_t kAnswerPiece = 64 << 10;

// Answers `file`'s bytes from `from` on, at most `max_length` of them, read
// piece by piece as they are sent; `*size`: the file's size. A request's
// `Range: bytes=A-B` (one range) is answered here, not by httplib (whose
// 0.11 answers a start past the end with a 206 of a wrapped length): 206 with
// the bytes from A to B (B past the end: to the end; `bytes=-N`: the last N),
// 416 when A is past the end; several ranges are ignored (the whole answer,
// as RFC 9110 allows). False when the file cannot be read.
bool AnswerFile(const fs::path& file, uint64_t from, uint64_t max_length,
                const std::string& content_type, const httplib::Request& req,
                httplib::Response* res, uint64_t* size) {
  // Only a regular file: a FIFO put in place after FileInside's check is
  // refused, never waited on.
  std::string why;
  const std::shared_ptr<const RegularFile> open = RegularFile::Open(file, &why);
  if (!open || open->CurrentSize() < 0) return false;
  *size = static_cast<uint64_t>(open->CurrentSize());
  uint64_t length = from >= *size ? 0 : std::min(*size - from, max_length);
  // httplib parsed the ranges into the request; taken from it here so that
  // it does not apply them again (the Request is httplib's own, not const).
  const httplib::Ranges ranges = req.ranges;
  const_cast<httplib::Request&>(req).ranges.clear();
  if (ranges.size() == 1) {
    const uint64_t available = length;
    const auto [first, last] = ranges.front();
    uint64_t start = 0, end = 0;  // [start, end) of the answer after `from`
    if (first < 0) {              // bytes=-N: the last N
      const uint64_t n = static_cast<uint64_t>(std::max<int64_t>(last, 0));
      start = available - std::min(n, available);
      end = n == 0 ? start : available;
    } else {
      start = static_cast<uint64_t>(first);
      end = last < 0 ? available : std::min(static_cast<uint64_t>(last) + 1, available);
    }
    if (start >= available || end <= start) {
      res->status = 416;
      res->set_header("Content-Range", "bytes */" + std::to_string(available));
      res->set_content(
          "range not satisfiable: the answer has " + std::to_string(available) + " bytes\n",
          "text/plain");
      return true;
    }
    res->status = 206;
    res->set_header("Content-Range", "bytes " + std::to_string(start) + "-" +
                                         std::to_string(end - 1) + "/" + std::to_string(available));
    from += start;
    length = end - start;
  }
  if (length == 0) {
    res->set_content("", content_type);
    return true;
  }
  res->set_content_provider(length, content_type,
                            [open, from](size_t offset, size_t left, httplib::DataSink& sink) {
                              std::string piece(std::min(left, kAnswerPiece), '\0');
                              return open->ReadAt(from + offset, piece.data(), piece.size()) &&
                                     sink.write(piece.data(), piece.size());
                            });
  return true;
}

// Connections served at once. A browser keeps a few idle sockets open per
// tab; a flood beyond this waits in the kernel's listen queue.
constexpr size_t kMaxConnections = 256;

// httplib's task queue: a thread of its own for each connection, up to
// kMaxConnections. (httplib's default, a pool of max(8, cores - 1)
// threads, let 8 idle connections -- two browser tabs' spare sockets --
// hold every thread for the keep-alive timeout while the next request
// waited.) At the cap, the listening thread waits for a connection to end
// before it accepts another: memory stays bounded, the flood queues in the
// kernel.
class ThreadPerConnection : public httplib::TaskQueue {
 public:
  ~ThreadPerConnection() override { shutdown(); }

  void enqueue(std::function<void()> task) override {
    std::unique_lock<std::mutex> lock(state_->mutex);
    state_->changed.wait(lock, [&] { return state_->running < kMaxConnections; });
    ++state_->running;
    lock.unlock();
    auto shared = std::make_shared<std::function<void()>>(std::move(task));
    try {
      // The thread holds the state, which outlives this queue until the last
      // connection's thread is done with it.
      std::thread([state = state_, shared] {
        (*shared)();
        std::lock_guard<std::mutex> done(state->mutex);
        --state->running;
        state->changed.notify_all();
      }).detach();
    } catch (const std::system_error&) {
      // No thread to be had (a process or memory limit): serve the
      // connection here, delaying the next accept, rather than drop it.
      (*shared)();
      std::lock_guard<std::mutex> done(state_->mutex);
      --state_->running;
      state_->changed.notify_all();
    }
  }

  // Waits until every connection's thread has answered and closed it
  // (within the read and keep-alive timeouts: the server socket is closed).
  void shutdown() override {
    std::unique_lock<std::mutex> lock(state_->mutex);
    state_->changed.wait(lock, [&] { return state_->running == 0; });
  }

 private:
  struct State {
    std::mutex mutex;
    std::condition_variable changed;
    size_t running = 0;
  };
  std::shared_ptr<State> state_ = std::make_shared<State>();
};

std::string ContentType(const fs::path& file) {
  const std::string ext = file.extension().string();
  if (ext == ".json") return "application/json";
  if (ext == ".csv" || ext == ".txt" || ext == ".yaml") return "text/plain; charset=utf-8";
  if (ext == ".png") return "image/png";
  if (ext == ".stl" || ext == ".obj") return "model/" + ext.substr(1);
  return "application/octet-stream";
}

class HttplibServer final : public HttpServer {
 public:
  explicit HttplibServer(HttpSite site);
  ~HttplibServer() override { http_.stop(); }

  int Bind(const std::string& host, int port) override {
    if (port == 0) return http_.bind_to_any_port(host);
    return http_.bind_to_port(host, port) ? port : -1;
  }
  void Run() override { http_.listen_after_bind(); }
  bool running() const override { return http_.is_running(); }
  void Stop() override { http_.stop(); }

 private:
  HttpSite site_;
  httplib::Server http_;
};

HttplibServer::HttplibServer(HttpSite site) : site_(std::move(site)) {
  httplib::Server& http = http_;
  // SO_REUSEADDR only: httplib's default SO_REUSEPORT would let a second
  // server share a port in use instead of saying so.
  http.set_socket_options([](int sock) {
    int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
  });
  // Hostile or stuck clients: small bodies, short timeouts. A request
  // arrives in one piece from a browser: one that stops halfway (or a
  // malformed one waiting for its end) is answered 400 after 1 s. An idle
  // connection, new or between requests, is closed after 1 s (browsers open
  // another), so it holds its thread no longer; a busy one is served up to
  // 100 requests.
  http.new_task_queue = [] { return new ThreadPerConnection; };
  http.set_payload_max_length(1 << 16);
  http.set_read_timeout(1, 0);
  http.set_write_timeout(30, 0);
  http.set_keep_alive_timeout(1);
  http.set_keep_alive_max_count(100);
  http.set_exception_handler(
      [](const httplib::Request&, httplib::Response& res, std::exception_ptr) {
        res.status = 500;
        res.set_content("internal error\n", "text/plain");
      });
  http.set_error_handler([](const httplib::Request&, httplib::Response& res) {
    if (res.body.empty()) res.set_content(std::to_string(res.status) + "\n", "text/plain");
  });

  // The page and its script.
  const auto page = [this](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    res.set_content(site_.page, "text/html; charset=utf-8");
  };
  http.Get("/", page);
  http.Get("/index.html", page);
  http.Get("/viewer.js", [this](const httplib::Request&, httplib::Response& res) {
    const std::string_view script = site_.script;
    res.set_content(script.data(), script.size(), "text/javascript; charset=utf-8");
  });
  http.Get("/favicon.ico",
           [](const httplib::Request&, httplib::Response& res) { res.status = 204; });

  // The recording from byte `from` on (a page following a run asks again
  // from where it is); X-Swarmsim-Size: the file's size now.
  http.Get("/recording.swrec", [this](const httplib::Request& req, httplib::Response& res) {
    uint64_t from = 0;
    if (req.has_param("from")) {
      const std::string text = req.get_param_value("from");
      const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), from);
      if (ec != std::errc() || end != text.data() + text.size()) {
        res.status = 400;
        res.set_content("from: expected a byte offset\n", "text/plain");
        return;
      }
    }
    const std::optional<fs::path> file = FileInside(site_.folder, kRecordingFile);
    uint64_t size = 0;
    if (!file || !AnswerFile(*file, from, kMaxRecordingAnswer, "application/octet-stream", req,
                             &res, &size)) {
      res.status = 404;
      return;
    }
    res.set_header("Cache-Control", "no-store");
    res.set_header("X-Swarmsim-Size", std::to_string(size));
  });

  // Other files of the folder the page may need (summary.json, meshes):
  // whole, however large (streamed piece by piece), never cut.
  http.Get("/files/(.+)", [this](const httplib::Request& req, httplib::Response& res) {
    const std::optional<fs::path> file = FileInside(site_.folder, req.matches[1].str());
    uint64_t size = 0;
    if (!file || !AnswerFile(*file, 0, UINT64_MAX, ContentType(*file), req, &res, &size))
      res.status = 404;
  });
}

HttpServer* MakeServer(const HttpSite& site, std::string* error) try {
  return new HttplibServer(site);
} catch (const std::exception& e) {
  *error = e.what();
  return nullptr;
}

}  // namespace

}  // namespace swarmsim::viewer

// The module's table (http_module.h).
extern "C" __attribute__((visibility("default"))) const void* swarmsim_http_module() {
  static const swarmsim::viewer::HttpModule module{swarmsim::viewer::kHttpModuleVersion,
                                                   swarmsim::viewer::MakeServer};
  return &module;
}
