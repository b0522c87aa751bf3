// Drives Debian's headless Chromium through chromedriver (WebDriver over
// HTTP, cpp-httplib's client) for the viewer's browser tests, and runs
// `swarmsim view` as a server process. Test-only.
#pragma once

#include <arpa/inet.h>
#include <fcntl.h>
#include <httplib.h>
#include <netinet/in.h>
#include <png.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace swarmsim::testing {

using nlohmann::json;

inline const char* kChromium = "/usr/bin/chromium";
inline const char* kChromedriver = "/usr/bin/chromedriver";

// Why the browser tests cannot run here ("" when they can).
inline std::string BrowserMissing() {
  for (const char* program : {kChromium, kChromedriver})
    if (::access(program, X_OK) != 0)
      return std::string(program) +
             " is not installed (tools/setup.sh installs chromium and "
             "chromium-driver): browser test skipped";
  return "";
}

// A TCP port free on 127.0.0.1 now.
inline int FreePort() {
  const int sock = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof(address);
  ::bind(sock, reinterpret_cast<sockaddr*>(&address), sizeof(address));
  ::getsockname(sock, reinterpret_cast<sockaddr*>(&address), &length);
  ::close(sock);
  return ntohs(address.sin_port);
}

// A child process (argv), its output to `log` (or /dev/null); killed with
// SIGTERM when destroyed.
class ChildProcess {
 public:
  ChildProcess(const std::vector<std::string>& argv, const std::string& log = "/dev/null") {
    pid_ = ::fork();
    if (pid_ == 0) {
      const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(fd, 1);
      ::dup2(fd, 2);
      std::vector<char*> args;
      for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
      args.push_back(nullptr);
      ::execv(args[0], args.data());
      ::_exit(127);
    }
  }
  ~ChildProcess() { Stop(); }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  // SIGTERM and wait; the exit status (or 128 + signal).
  int Stop() {
    if (pid_ <= 0) return status_;
    ::kill(pid_, SIGTERM);
    return Wait();
  }
  int Wait() {
    if (pid_ <= 0) return status_;
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
    status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return status_;
  }
  bool Running() {
    if (pid_ <= 0) return false;
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == 0) return true;
    pid_ = -1;
    status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return false;
  }

 private:
  pid_t pid_ = -1;
  int status_ = -1;
};

// Waits until `condition()` holds or `seconds` pass; whether it held.
template <typename Condition>
bool WaitUntil(Condition condition, double seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!condition()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

// The text of a file ("" if none).
inline std::string FileText(const std::string& path) {
  std::string text;
  if (FILE* f = std::fopen(path.c_str(), "rb")) {
    char buffer[4096];
    size_t n;
    while ((n = std::fread(buffer, 1, sizeof(buffer), f)) > 0) text.append(buffer, n);
    std::fclose(f);
  }
  return text;
}

// `swarmsim view DIR --port 0 ARGS` running; address() once it printed it.
class ViewServer {
 public:
  ViewServer(const std::string& folder, const std::string& log,
             const std::vector<std::string>& extra = {})
      : log_(log), process_(Args(folder, extra), log) {
    WaitUntil([&] { return !Address().empty() || !process_.Running(); }, 20);
  }
  // http://127.0.0.1:PORT/ from the server's first line; "" if none yet.
  std::string Address() {
    const std::string text = FileText(log_);
    const size_t at = text.find("http://");
    if (at == std::string::npos) return "";
    const size_t end = text.find(' ', at);
    return end == std::string::npos ? "" : text.substr(at, end - at);
  }
  std::string Output() { return FileText(log_); }
  ChildProcess& process() { return process_; }

 private:
  static std::vector<std::string> Args(const std::string& folder,
                                       const std::vector<std::string>& extra) {
    std::vector<std::string> args = {SWARMSIM_BINARY, "view", folder, "--port", "0"};
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  }
  std::string log_;
  ChildProcess process_;
};

// An RGBA screenshot.
struct Image {
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;
  const uint8_t* At(int x, int y) const { return &rgba[4 * (size_t(y) * width + x)]; }
};

inline Image DecodePng(const std::string& bytes) {
  Image image;
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&png, bytes.data(), bytes.size())) return image;
  png.format = PNG_FORMAT_RGBA;
  image.width = png.width;
  image.height = png.height;
  image.rgba.resize(PNG_IMAGE_SIZE(png));
  if (!png_image_finish_read(&png, nullptr, image.rgba.data(), 0, nullptr)) image = Image{};
  return image;
}

inline std::string DecodeBase64(const std::string& text) {
  std::string out;
  int bits = 0, value = 0;
  for (const char c : text) {
    int digit;
    if (c >= 'A' && c <= 'Z')
      digit = c - 'A';
    else if (c >= 'a' && c <= 'z')
      digit = c - 'a' + 26;
    else if (c >= '0' && c <= '9')
      digit = c - '0' + 52;
    else if (c == '+')
      digit = 62;
    else if (c == '/')
      digit = 63;
    else
      continue;
    value = (value << 6) | digit;
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((value >> bits) & 0xff);
    }
  }
  return out;
}

// One headless Chromium session through chromedriver.
class Browser {
 public:
  Browser(int width = 1000, int height = 700)
      : port_(FreePort()),
        driver_({kChromedriver, "--port=" + std::to_string(port_)}),
        client_("127.0.0.1", port_) {
    client_.set_read_timeout(60, 0);
    WaitUntil([&] { return client_.Get("/status") != nullptr; }, 20);
    const json capabilities = {
        {"capabilities",
         {{"alwaysMatch",
           {{"goog:loggingPrefs", {{"browser", "ALL"}}},
            {"goog:chromeOptions",
             {{"binary", kChromium},
              {"args",
               {"--headless=new", "--no-sandbox", "--enable-unsafe-swiftshader",
                "--disable-dev-shm-usage", "--hide-scrollbars",
                "--window-size=" + std::to_string(width) + "," + std::to_string(height)}}}}}}}}};
    const json session = Call("POST", "/session", capabilities);
    session_ = session.value("sessionId", "");
    if (session_.empty()) throw std::runtime_error("no WebDriver session: " + session.dump());
  }
  ~Browser() {
    if (!session_.empty()) Call("DELETE", "/session/" + session_, nullptr);
  }

  void Open(const std::string& url) { Call("POST", Path("/url"), {{"url", url}}); }
  // Runs `body` (a function body; `return` gives the result) in the page.
  json Run(const std::string& body) {
    return Call("POST", Path("/execute/sync"), {{"script", body}, {"args", json::array()}});
  }
  // Runs `body` as an async function in the page and waits for its result.
  json RunAsync(const std::string& body) {
    const std::string script =
        "const done = arguments[arguments.length - 1];"
        "(async () => {" +
        body + "})().then(done, (e) => done('error: ' + e));";
    return Call("POST", Path("/execute/async"), {{"script", script}, {"args", json::array()}});
  }
  // Waits until the viewer is ready or says why not: its error, or "".
  std::string WaitForViewer(double seconds = 20) {
    json state;
    WaitUntil(
        [&] {
          state =
              Run("const v = window.swarmsimViewer;"
                  "return v ? {ready: v.ready, error: v.error} : null;");
          return state.is_object() && (state["ready"] == true || !state["error"].is_null());
        },
        seconds);
    if (!state.is_object()) return "the page has no window.swarmsimViewer";
    if (!state["error"].is_null()) return state["error"].get<std::string>();
    return state["ready"] == true ? "" : "the viewer did not get ready in time";
  }
  Image Screenshot() {
    return DecodePng(DecodeBase64(Call("GET", Path("/screenshot"), nullptr).get<std::string>()));
  }
  // A left click at page pixel (x, y).
  void Click(int x, int y) {
    const json actions = {
        {"actions",
         {{{"type", "pointer"},
           {"id", "mouse"},
           {"parameters", {{"pointerType", "mouse"}}},
           {"actions",
            {{{"type", "pointerMove"}, {"duration", 0}, {"x", x}, {"y", y}, {"origin", "viewport"}},
             {{"type", "pointerDown"}, {"button", 0}},
             {{"type", "pointerUp"}, {"button", 0}}}}}}}};
    Call("POST", Path("/actions"), actions);
  }
  // The console's errors (level SEVERE) since the last call.
  std::vector<std::string> ConsoleErrors() {
    std::vector<std::string> errors;
    const json log = Call("POST", Path("/se/log"), {{"type", "browser"}});
    if (log.is_array())
      for (const json& entry : log)
        if (entry.value("level", "") == "SEVERE") errors.push_back(entry.value("message", ""));
    return errors;
  }

 private:
  std::string Path(const std::string& what) const { return "/session/" + session_ + what; }
  json Call(const std::string& method, const std::string& path, const json& body) {
    httplib::Result result = method == "GET" ? client_.Get(path.c_str())
                             : method == "DELETE"
                                 ? client_.Delete(path.c_str())
                                 : client_.Post(path.c_str(), body.dump(), "application/json");
    if (!result) throw std::runtime_error("chromedriver: no answer to " + method + " " + path);
    const json answer = json::parse(result->body, nullptr, false);
    if (result->status != 200)
      throw std::runtime_error("chromedriver: " + method + " " + path + ": " + result->body);
    return answer.is_object() && answer.contains("value") ? answer["value"] : json();
  }

  int port_;
  ChildProcess driver_;
  httplib::Client client_;
  std::string session_;
};

}  // namespace swarmsim::testing
