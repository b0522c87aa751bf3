// The HTTP server of `swarmsim view` (cpp-httplib): the page, its script,
// the recording from a byte offset, and other files of the output folder.
#include "swarm/viewer/server.h"

#include <httplib.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <system_error>
#include <thread>

#include "framework/error.h"
#include "framework/regular_file.h"
#include "swarm/viewer/assets.h"
#include "swarm/viewer/page.h"

namespace swarmsim::viewer {
namespace fs = std::filesystem;

namespace {

// At most this many bytes in one answer for the recording: a page reading a
// larger file asks again from where the answer ended.
constexpr uint64_t kMaxRecordingAnswer = 64ull << 20;
// An answer's bytes are read from the file in pieces of this size as they
// are sent, so a connection holds no more of them (kMaxConnections at once).
constexpr size_t kAnswerPiece = 64 << 10;

// Answers `file`'s bytes from `from` on, at most kMaxRecordingAnswer of
// them, read piece by piece as they are sent; `*size`: the file's size.
// False when the file cannot be read.
bool AnswerFile(const fs::path& file, uint64_t from, const std::string& content_type,
                httplib::Response* res, uint64_t* size) {
  // Only a regular file: a FIFO put in place after FileInside's check is
  // refused, never waited on.
  std::string why;
  const std::shared_ptr<const RegularFile> open = RegularFile::Open(file, &why);
  if (!open || open->CurrentSize() < 0) return false;
  *size = static_cast<uint64_t>(open->CurrentSize());
  const uint64_t length = from >= *size ? 0 : std::min(*size - from, kMaxRecordingAnswer);
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

}  // namespace

std::optional<fs::path> FileInside(const fs::path& folder, std::string_view request_path) {
  // A relative path of plain names: no `..`, `.`, empty part, NUL or leading '/'.
  if (request_path.empty() || request_path.front() == '/') return std::nullopt;
  if (request_path.find('\0') != std::string_view::npos) return std::nullopt;
  const fs::path relative(request_path);
  if (relative.is_absolute() || relative.has_root_name()) return std::nullopt;
  for (const fs::path& part : relative)
    if (part.empty() || part == ".." || part == ".") return std::nullopt;
  // Resolved through every symbolic link, it must still be inside the folder.
  std::error_code error;
  const fs::path root = fs::canonical(folder, error);
  if (error) return std::nullopt;
  const fs::path file = fs::canonical(root / relative, error);
  if (error) return std::nullopt;
  const auto [root_end, file_it] =
      std::mismatch(root.begin(), root.end(), file.begin(), file.end());
  if (root_end != root.end() || file_it == file.end()) return std::nullopt;
  if (!fs::is_regular_file(file, error)) return std::nullopt;
  return file;
}

struct Server::Impl {
  fs::path folder;
  httplib::Server http;
  std::string host;
  int port = 0;
};

Server::Server(fs::path folder) : impl_(std::make_unique<Impl>()) {
  impl_->folder = std::move(folder);
  httplib::Server& http = impl_->http;
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
  const auto page = [](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    res.set_content(ServedPage(), "text/html; charset=utf-8");
  };
  http.Get("/", page);
  http.Get("/index.html", page);
  http.Get("/viewer.js", [](const httplib::Request&, httplib::Response& res) {
    const std::string_view script = PageScript();
    res.set_content(script.data(), script.size(), "text/javascript; charset=utf-8");
  });
  http.Get("/favicon.ico",
           [](const httplib::Request&, httplib::Response& res) { res.status = 204; });

  // The recording from byte `from` on (a page following a run asks again
  // from where it is); X-Swarmsim-Size: the file's size now.
  Impl* impl = impl_.get();
  http.Get("/recording.swrec", [impl](const httplib::Request& req, httplib::Response& res) {
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
    const std::optional<fs::path> file = FileInside(impl->folder, kRecordingFile);
    uint64_t size = 0;
    if (!file || !AnswerFile(*file, from, "application/octet-stream", &res, &size)) {
      res.status = 404;
      return;
    }
    res.set_header("Cache-Control", "no-store");
    res.set_header("X-Swarmsim-Size", std::to_string(size));
  });

  // Other files of the folder the page may need (summary.json, meshes).
  http.Get("/files/(.+)", [impl](const httplib::Request& req, httplib::Response& res) {
    const std::optional<fs::path> file = FileInside(impl->folder, req.matches[1].str());
    uint64_t size = 0;
    if (!file || !AnswerFile(*file, 0, ContentType(*file), &res, &size)) res.status = 404;
  });
}

Server::~Server() { Stop(); }

int Server::Bind(const std::string& host, int port) {
  const bool bound = port == 0 ? (port = impl_->http.bind_to_any_port(host)) > 0
                               : impl_->http.bind_to_port(host, port);
  if (!bound)
    throw Error("cannot listen on " + host + ":" + (port > 0 ? std::to_string(port) : "0") +
                ": the port is in use or the address is not this machine's (--port 0 picks a "
                "free port)");
  impl_->host = host;
  impl_->port = port;
  return port;
}

std::string Server::Address() const {
  const bool ipv6 = impl_->host.find(':') != std::string::npos;
  return "http://" + (ipv6 ? "[" + impl_->host + "]" : impl_->host) + ":" +
         std::to_string(impl_->port) + "/";
}

void Server::Run() { impl_->http.listen_after_bind(); }

void Server::Start() {
  thread_ = std::thread([this] { Run(); });
}

void Server::Stop() {
  // A server started on another thread may not be listening yet.
  for (int i = 0; thread_.joinable() && !impl_->http.is_running() && i < 2000; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  impl_->http.stop();
  if (thread_.joinable()) thread_.join();
}

}  // namespace swarmsim::viewer
