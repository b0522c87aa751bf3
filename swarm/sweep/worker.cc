#include "swarm/sweep/worker.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/signalfd.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "framework/csv.h"
#include "framework/error.h"
#include "framework/utf8.h"

namespace swarmsim {
namespace {

static_assert(sizeof(sigset_t) <= 128, "RunPool::old_mask_ too small");

// The last non-empty lines of a child's stderr, for a failure message.
std::string Tail(const std::string& text, int lines) {
  std::vector<std::string> all;
  std::istringstream s(text);
  std::string line;
  while (std::getline(s, line))
    if (!line.empty()) all.push_back(line);
  std::string out;
  for (size_t i = all.size() > static_cast<size_t>(lines) ? all.size() - lines : 0; i < all.size();
       ++i)
    out += (out.empty() ? "" : " | ") + all[i];
  return out;
}

// A number as metrics.csv writes it, the whole field: a subnormal value
// (1e-320: strtod's ERANGE, std::stod's out_of_range) is a number too.
bool ParseNumber(const std::string& field, double* value) {
  if (field.empty() || std::isspace(static_cast<unsigned char>(field[0]))) return false;
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(field.c_str(), &end);
  if (end != field.c_str() + field.size()) return false;
  if (errno == ERANGE && std::isinf(v)) return false;  // past the largest double
  *value = v;
  return true;
}

// metrics.csv (step,time,robot,metric,value) -> series and final values.
// Swarm metrics (robot empty) are kept as they are; a per-robot metric
// becomes its mean over the robots that recorded it in that step. Metric
// names are read as the CSV quotes them ('a,b' was stored as 'b"').
void ReadMetrics(const std::filesystem::path& path, RunOutcome* out) {
  std::ifstream f(path, std::ios::binary);
  std::vector<std::string> fields;
  if (!ReadCsvRecord(f, &fields)) return;  // header
  struct Key {
    std::string metric;
    int64_t step;
    bool operator<(const Key& o) const {
      return metric != o.metric ? metric < o.metric : step < o.step;
    }
  };
  // The robots' values of a step: their sum, and their sum scaled by 2^-64
  // (exact), for a mean whose sum passes the largest double (robots of
  // 1.5e308 each: inf otherwise).
  constexpr int kScale = 64;
  struct Acc {
    double time = 0, sum = 0, scaled = 0;
    int64_t n = 0;
    bool finite = true;
  };
  std::map<Key, Acc> acc;
  while (ReadCsvRecord(f, &fields)) {
    if (fields.size() != 5) continue;
    // Every field read before the row counts: a torn last line ("3,0.3,bot#0,x")
    // is no record, and a field that is no number skips its row.
    try {
      size_t used = 0;
      const int64_t step = std::stoll(fields[0], &used);
      if (used != fields[0].size()) continue;
      double time = 0, value = 0;
      if (!ParseNumber(fields[1], &time) || !ParseNumber(fields[4], &value)) continue;
      Acc& a = acc[Key{fields[3], step}];
      a.time = time;
      a.sum += value;
      a.scaled += std::ldexp(value, -kScale);
      a.finite = a.finite && std::isfinite(value);
      ++a.n;
    } catch (const std::exception&) {
      continue;
    }
  }
  for (const auto& [key, a] : acc) {
    const double n = static_cast<double>(a.n);
    const double value =
        std::isfinite(a.sum) || !a.finite ? a.sum / n : std::ldexp(a.scaled / n, kScale);
    out->series.push_back({key.metric, key.step, a.time, value});
    out->final_metrics[key.metric] = value;  // steps ascend within a metric: the last wins
  }
}

}  // namespace

std::string WorkerName() {
  char host[256] = {0};
  gethostname(host, sizeof host - 1);
  return std::string(host) + ":" + std::to_string(getpid());
}

std::vector<std::string> RunArguments(const WorkerConfig& config, const GridRun& run,
                                      const std::filesystem::path& out_dir) {
  std::vector<std::string> args{"run", config.world, "--seed", std::to_string(run.seed)};
  for (const auto& [name, value] : run.params) {
    args.push_back("--set");
    args.push_back(name + "=" + value);
  }
  if (config.steps) {
    args.push_back("--steps");
    args.push_back(std::to_string(*config.steps));
  } else if (config.duration) {
    args.push_back("--duration");
    args.push_back(FormatNumber(*config.duration));
  }
  args.push_back("--threads");
  args.push_back(std::to_string(config.threads_per_run));
  if (!config.max_memory.empty()) {
    args.push_back("--max-memory");
    args.push_back(config.max_memory);
  }
  args.push_back("--quiet");
  args.push_back("--out");
  args.push_back(out_dir.string());
  return args;
}

bool IsMachineFailure(const std::string& error) {
  for (const char* sign : {"No space left on device", "Disk quota exceeded", "Too many open files",
                           "Resource temporarily unavailable", "cannot start a thread for",
                           "cannot start the worker program", "Read-only file system"})
    if (error.find(sign) != std::string::npos) return true;
  return false;
}

RunOutcome CollectRun(int64_t id, const std::filesystem::path& out_dir,
                      const std::string& stderr_text, int wait_status, bool timed_out,
                      double timeout_s) {
  RunOutcome o;
  o.id = id;
  const std::string err = Tail(stderr_text, 3);
  nlohmann::json summary;
  bool have_summary = false;
  try {
    std::ifstream f(out_dir / "summary.json");
    if (f) {
      summary = nlohmann::json::parse(f);
      have_summary = true;
    }
  } catch (const std::exception&) {
  }
  // A run killed mid-way leaves its first summary ("running", no hash yet):
  // each field read only when it has the type it should.
  const auto field = [&](const char* key) -> const nlohmann::json* {
    if (!have_summary || !summary.is_object()) return nullptr;
    const auto it = summary.find(key);
    return it == summary.end() ? nullptr : &*it;
  };
  if (const nlohmann::json* steps = field("steps"); steps && steps->is_number_integer())
    o.steps = steps->get<int64_t>();
  if (const nlohmann::json* robots = field("robots"); robots && robots->is_number_integer())
    o.robots = robots->get<int64_t>();
  if (const nlohmann::json* hash = field("state_hash"); hash && hash->is_string())
    o.state_hash = hash->get<std::string>();
  const nlohmann::json* status = field("status");
  const nlohmann::json* error = field("error");
  ReadMetrics(out_dir / "metrics.csv", &o);
  if (timed_out) {
    o.error = "timed out after " + FormatNumber(timeout_s) + " s (--timeout)";
    o.state_hash.clear();
  } else if (WIFSIGNALED(wait_status)) {
    const int sig = WTERMSIG(wait_status);
    o.error = "crashed: killed by signal " + std::to_string(sig) + " (" + strsignal(sig) + ")";
    if (!err.empty()) o.error += ": " + err;
  } else if (!WIFEXITED(wait_status) || WEXITSTATUS(wait_status) != 0) {
    if (error && error->is_string())
      o.error = error->get<std::string>();
    else if (!err.empty())
      o.error = err;
    else
      o.error = "exit status " + std::to_string(WEXITSTATUS(wait_status));
    if (WIFEXITED(wait_status) && WEXITSTATUS(wait_status) == 127 && err.empty())
      o.error = "cannot start the worker program";
  } else if (!status || !status->is_string() || status->get<std::string>() != "ok") {
    o.error = "the run wrote no valid summary.json";
  } else {
    o.ok = true;
  }
  o.error = ValidUtf8(o.error);  // stderr's tail may hold any bytes
  // (A timeout or a crash is the run's, whatever it said before.)
  o.machine = !o.ok && !timed_out && WIFEXITED(wait_status) &&
              (IsMachineFailure(o.error) || IsMachineFailure(err));
  return o;
}

RunPool::RunPool(const WorkerConfig& config, int slots)
    : config_(config), slots_(std::max(1, slots)), worker_name_(WorkerName()) {
  sigset_t block;
  sigemptyset(&block);
  sigaddset(&block, SIGCHLD);
  restore_mask_ = pthread_sigmask(SIG_BLOCK, &block, reinterpret_cast<sigset_t*>(old_mask_)) == 0;
  child_fd_ = signalfd(-1, &block, SFD_NONBLOCK | SFD_CLOEXEC);
  if (child_fd_ < 0)
    throw Error(std::string("cannot watch the runs (signalfd): ") + std::strerror(errno));
  std::filesystem::create_directories(config_.scratch);
  // Scratch folders of sweeps that were killed (their process is gone).
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(config_.scratch.parent_path(), ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("swarmsim-sweep-", 0) != 0) continue;
    const std::string pid = name.substr(15);
    if (pid.empty() || pid.find_first_not_of("0123456789") != std::string::npos) continue;
    if (kill(static_cast<pid_t>(std::stol(pid)), 0) == -1 && errno == ESRCH)
      std::filesystem::remove_all(entry.path(), ec);
  }
}

void RunPool::Drain(Active* a) {
  char buffer[4096];
  while (a->err_fd >= 0) {
    const ssize_t n = ::read(a->err_fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno == EAGAIN) return;  // more may come
    if (n <= 0) {                          // its end (or an error: nothing more to read)
      ::close(a->err_fd);
      a->err_fd = -1;
      return;
    }
    a->err.append(buffer, static_cast<size_t>(n));
    if (a->err.size() > 2 * kErrKeep) a->err.erase(0, a->err.size() - kErrKeep);
  }
}

int RunPool::KillAll() {
  const int killed = active();
  for (Active& a : active_) {
    kill(a.pid, SIGKILL);
    waitpid(a.pid, nullptr, 0);
    if (a.err_fd >= 0) ::close(a.err_fd);
    std::error_code ec;
    std::filesystem::remove_all(a.dir, ec);
  }
  active_.clear();
  return killed;
}

RunPool::~RunPool() {
  KillAll();
  std::error_code ec;
  std::filesystem::remove(config_.scratch, ec);  // only if empty
  ::close(child_fd_);
  if (restore_mask_) {
    // Drain a SIGCHLD left pending so it does not reach the old mask's handler later.
    sigset_t chld;
    sigemptyset(&chld);
    sigaddset(&chld, SIGCHLD);
    timespec zero{0, 0};
    while (sigtimedwait(&chld, nullptr, &zero) > 0) {
    }
    pthread_sigmask(SIG_SETMASK, reinterpret_cast<sigset_t*>(old_mask_), nullptr);
  }
}

void RunPool::Start(const GridRun& run) {
  const std::filesystem::path dir = config_.scratch / ("run-" + std::to_string(run.id));
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error("cannot create '" + dir.string() + "': " + ec.message());
  std::vector<std::string> args = RunArguments(config_, run, dir);
  args.insert(args.begin(), config_.self_exe);
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  // Its stderr through a pipe, not a file in the scratch folder: on a full
  // disk the file kept nothing, and the run's message was lost.
  int err_pipe[2];
  if (pipe2(err_pipe, O_CLOEXEC) != 0)
    throw Error(std::string("cannot start a worker process: ") + strerror(errno));
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) {
    const int error = errno;
    ::close(err_pipe[0]);
    ::close(err_pipe[1]);
    throw Error(std::string("cannot start a worker process: ") + strerror(error));
  }
  if (pid == 0) {
    // The child: die with the sweep, no inherited signal mask, quiet stdout.
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(126);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    const int null_fd = open("/dev/null", O_RDWR);
    if (null_fd >= 0) {
      dup2(null_fd, STDIN_FILENO);
      dup2(null_fd, STDOUT_FILENO);
    }
    dup2(err_pipe[1], STDERR_FILENO);  // (dup2's copy is not closed on exec)
    execv(argv[0], argv.data());
    _exit(127);
  }
  ::close(err_pipe[1]);
  fcntl(err_pipe[0], F_SETFL, O_NONBLOCK);
  active_.push_back({run.id, pid, dir, Clock::now(), err_pipe[0], {}});
}

std::vector<RunOutcome> RunPool::Poll(double wait_s) {
  std::vector<RunOutcome> done;
  if (active_.empty()) return done;
  // Wait for SIGCHLD, but not past the earliest time limit.
  auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                     std::chrono::duration<double>(std::max(0.0, wait_s)));
  if (config_.timeout_s > 0)
    for (const Active& a : active_)
      deadline =
          std::min(deadline, a.start + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(config_.timeout_s)));
  // Until a run ends (SIGCHLD), the deadline or a stop signal (EINTR: the
  // handlers do not restart), reading what the runs write on stderr (a run
  // whose pipe is full waits for it).
  for (;;) {
    const double wait = std::chrono::duration<double>(deadline - Clock::now()).count();
    std::vector<pollfd> fds{{child_fd_, POLLIN, 0}};
    for (const Active& a : active_)
      if (a.err_fd >= 0) fds.push_back({a.err_fd, POLLIN, 0});
    const int ready =
        poll(fds.data(), fds.size(), wait > 0 ? static_cast<int>(std::ceil(wait * 1e3)) : 0);
    if (ready <= 0) break;  // the deadline, or a signal
    for (Active& a : active_) Drain(&a);
    if (fds[0].revents != 0) {
      signalfd_siginfo info;
      while (::read(child_fd_, &info, sizeof info) == static_cast<ssize_t>(sizeof info)) {
      }
      break;
    }
    if (wait <= 0) break;
  }
  const auto now = Clock::now();
  for (size_t i = 0; i < active_.size();) {
    Active& a = active_[i];
    int status = 0;
    bool timed_out = false;
    pid_t r = waitpid(a.pid, &status, WNOHANG);
    if (r == 0 && config_.timeout_s > 0 &&
        std::chrono::duration<double>(now - a.start).count() >= config_.timeout_s) {
      kill(a.pid, SIGKILL);
      r = waitpid(a.pid, &status, 0);
      timed_out = true;
    }
    if (r == 0) {
      ++i;
      continue;
    }
    Drain(&a);  // the rest: the run has ended
    if (a.err_fd >= 0) ::close(a.err_fd);
    RunOutcome o = CollectRun(a.id, a.dir, a.err, status, timed_out, config_.timeout_s);
    o.wall_s = std::chrono::duration<double>(Clock::now() - a.start).count();
    o.worker = worker_name_;
    done.push_back(std::move(o));
    std::error_code ec;
    std::filesystem::remove_all(a.dir, ec);
    active_.erase(active_.begin() + static_cast<std::ptrdiff_t>(i));
  }
  return done;
}

}  // namespace swarmsim
