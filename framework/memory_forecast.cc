// Memory forecasts for large worlds (memory_forecast.h).
#include "framework/memory_forecast.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <tuple>
#include <utility>

namespace swarmsim {
namespace {

// Checks start once this many items are built (fewer give a noisy growth:
// with huge pages the resident size moves 2 MiB at a time).
constexpr int64_t kFirstCheck = 1000;
// Worlds smaller than this are never checked.
constexpr int64_t kMinItems = kForecastMinRobots;

// The process's sizes in bytes (/proc/self/statm): mapped, resident and
// data (+ stack); all zero if unreadable.
struct ProcessSizes {
  uint64_t mapped = 0, resident = 0, data = 0;
};
ProcessSizes ReadProcessSizes() {
  std::ifstream in("/proc/self/statm");
  uint64_t size = 0, resident = 0, shared = 0, text = 0, lib = 0, data = 0;
  if (!(in >> size >> resident >> shared >> text >> lib >> data)) return {};
  const uint64_t page = static_cast<uint64_t>(sysconf(_SC_PAGESIZE));
  return {size * page, resident * page, data * page};
}

uint64_t ResidentBytes() { return ReadProcessSizes().resident; }

// MemAvailable + SwapFree from /proc/meminfo; UINT64_MAX if unreadable.
uint64_t MachineAvailable() {
  std::ifstream in("/proc/meminfo");
  std::string key, unit;
  uint64_t value = 0, available = 0, swap_free = 0;
  bool found = false;
  while (in >> key >> value) {
    std::getline(in, unit);
    if (key == "MemAvailable:") {
      available = value * 1024;
      found = true;
    } else if (key == "SwapFree:") {
      swap_free = value * 1024;
    }
  }
  return found ? available + swap_free : UINT64_MAX;
}

uint64_t ReadNumber(const std::string& path, bool* ok) {
  std::ifstream in(path);
  std::string text;
  *ok = false;
  if (!(in >> text)) return 0;
  char* end = nullptr;
  const unsigned long long v = std::strtoull(text.c_str(), &end, 10);
  if (end == text.c_str() || *end != '\0') return 0;  // "max"
  *ok = true;
  return v;
}

// The sum of `keys`' values in a cgroup's memory.stat ("file 123" lines).
uint64_t StatSum(const std::string& path, std::initializer_list<const char*> keys) {
  std::ifstream in(path);
  std::string key;
  uint64_t value = 0, sum = 0;
  while (in >> key >> value)
    for (const char* k : keys)
      if (key == k) sum += value;
  return sum;
}

// Room under one cgroup's limit: the limit less what the group holds, its
// page cache (reclaimable, as in MemAvailable) not counted.
uint64_t RoomUnder(uint64_t limit, uint64_t usage, uint64_t cache) {
  const uint64_t held = usage > cache ? usage - cache : 0;
  return limit > held ? limit - held : 0;
}

// The least room a cgroup limit leaves (v2: the process's group and its
// ancestors; v1: the memory controller's hierarchical limit); UINT64_MAX
// without one.
uint64_t CgroupAvailable() {
  std::ifstream in("/proc/self/cgroup");
  std::string line, v2_path, v1_path;
  while (std::getline(in, line)) {
    if (line.rfind("0::", 0) == 0) v2_path = line.substr(3);
    const size_t memory = line.find(":memory:");
    if (memory != std::string::npos) v1_path = line.substr(memory + 8);
  }
  uint64_t room = UINT64_MAX;
  for (std::string path = v2_path; !path.empty();) {
    const std::string dir = "/sys/fs/cgroup" + (path == "/" ? std::string() : path);
    bool has_max = false, has_current = false;
    const uint64_t max = ReadNumber(dir + "/memory.max", &has_max);
    const uint64_t current = ReadNumber(dir + "/memory.current", &has_current);
    if (has_max && has_current)
      room = std::min(
          room,
          RoomUnder(max, current, StatSum(dir + "/memory.stat", {"active_file", "inactive_file"})));
    if (path == "/") break;
    const size_t slash = path.rfind('/');
    path = slash == 0 || slash == std::string::npos ? "/" : path.substr(0, slash);
  }
  if (!v1_path.empty()) {
    const std::string dir = "/sys/fs/cgroup/memory" + (v1_path == "/" ? std::string() : v1_path);
    bool has_usage = false;
    const uint64_t usage = ReadNumber(dir + "/memory.usage_in_bytes", &has_usage);
    const uint64_t limit = StatSum(dir + "/memory.stat", {"hierarchical_memory_limit"});
    // Unlimited reads as the largest page-aligned number (~2^63).
    if (has_usage && limit > 0 && limit < (uint64_t{1} << 62))
      room = std::min(room, RoomUnder(limit, usage,
                                      StatSum(dir + "/memory.stat",
                                              {"total_active_file", "total_inactive_file"})));
  }
  return room;
}

// Room under the process's own limits: its address space (ulimit -v) less
// what it has mapped, its data segment (ulimit -d) less its data size (what
// malloc takes counts against both); UINT64_MAX without either. `*which`
// names the nearer one.
uint64_t LimitAvailable(const ProcessSizes& sizes, const char** which) {
  uint64_t room = UINT64_MAX;
  for (const auto& [resource, used, name] :
       {std::tuple{RLIMIT_AS, sizes.mapped, "the address-space limit (ulimit -v)"},
        std::tuple{RLIMIT_DATA, sizes.data, "the data-size limit (ulimit -d)"}}) {
    rlimit limit{};
    if (getrlimit(resource, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) continue;
    const uint64_t left = limit.rlim_cur > used ? limit.rlim_cur - used : 0;
    if (left < room) {
      room = left;
      *which = name;
    }
  }
  return room;
}

}  // namespace

std::string GroupThousands(int64_t n) {
  const std::string digits = std::to_string(n < 0 ? 0 : n);
  std::string out;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

namespace {
std::string Lowered(const char* value) {
  std::string v(value);
  std::transform(v.begin(), v.end(), v.begin(), [](unsigned char c) { return std::tolower(c); });
  return v;
}
}  // namespace

bool IsOffValue(const char* value) {
  if (value == nullptr) return false;
  const std::string v = Lowered(value);
  return v == "0" || v == "off" || v == "false" || v == "no";
}

bool IsOnValue(const char* value) {
  if (value == nullptr) return false;
  const std::string v = Lowered(value);
  return v == "1" || v == "on" || v == "true" || v == "yes";
}

std::string FormatSize(double bytes) {
  static const char* const kUnits[] = {"bytes", "KiB", "MiB", "GiB", "TiB"};
  int unit = 0;
  while (bytes >= 1024 && unit < 4) {
    bytes /= 1024;
    ++unit;
  }
  char text[48];
  if (unit == 0)
    std::snprintf(text, sizeof text, "%.0f bytes", bytes);
  else
    std::snprintf(text, sizeof text, bytes < 100 ? "%.1f %s" : "%.0f %s", bytes, kUnits[unit]);
  return text;
}

bool ParseMemorySize(const std::string& text, uint64_t* bytes) {
  size_t end = 0;
  double value = 0;
  try {
    value = std::stod(text, &end);
  } catch (const std::exception&) {
    return false;
  }
  std::string unit = text.substr(end);
  std::transform(unit.begin(), unit.end(), unit.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  double scale = 1;
  if (unit == "k" || unit == "kib" || unit == "kb")
    scale = 1024.0;
  else if (unit == "m" || unit == "mib" || unit == "mb")
    scale = 1024.0 * 1024;
  else if (unit == "g" || unit == "gib" || unit == "gb")
    scale = 1024.0 * 1024 * 1024;
  else if (unit == "t" || unit == "tib" || unit == "tb")
    scale = 1024.0 * 1024 * 1024 * 1024;
  else if (!unit.empty() && unit != "b")
    return false;
  const double b = value * scale;
  if (!std::isfinite(b) || b < 1 || b > 1.8e19 || text.empty() || std::isspace(text[0]))
    return false;
  *bytes = static_cast<uint64_t>(b);
  return true;
}

MemoryRoom ReadMemoryRoom(uint64_t cap) {
  MemoryRoom room;
  const ProcessSizes sizes = ReadProcessSizes();
  room.resident = sizes.resident;
  const uint64_t machine = MachineAvailable();
  if (machine != UINT64_MAX) {
    room.available = machine;
    room.bound = "this machine's available memory and swap";
  }
  if (const uint64_t group = CgroupAvailable(); group < room.available) {
    room.available = group;
    room.bound = "the memory limit of the process's cgroup";
  }
  const char* which = nullptr;
  if (const uint64_t own = LimitAvailable(sizes, &which); own < room.available) {
    room.available = own;
    room.bound = which;
  }
  if (cap > 0) {
    const uint64_t left = cap > room.resident ? cap - room.resident : 0;
    if (left < room.available) {
      room.available = left;
      room.bound = "--max-memory " + FormatSize(static_cast<double>(cap));
    }
  }
  return room;
}

std::string NoRoomLeft(int64_t robots, const std::string& after, uint64_t cap) {
  if (robots < kMinItems || IsOffValue(std::getenv("SWARMSIM_MEMORY_CHECK"))) return "";
  const MemoryRoom room = ReadMemoryRoom(cap);
  if (room.available != 0) return "";
  return "not enough memory for " + GroupThousands(robots) + " robots: after " + after +
         " the process holds " + FormatSize(static_cast<double>(room.resident)) +
         ", with no room left (" + room.bound +
         "). Run fewer robots or give the run more memory (README, \"A world that does not "
         "fit\"); SWARMSIM_MEMORY_CHECK=0 skips this check";
}

MemoryForecast::MemoryForecast(std::string items, int64_t total, uint64_t cap)
    : items_(std::move(items)), total_(total), cap_(cap) {
  if (total_ < kMinItems || IsOffValue(std::getenv("SWARMSIM_MEMORY_CHECK"))) return;
  stride_ = std::max<int64_t>(kFirstCheck, total_ / 64);
}

std::string MemoryForecast::Built(int64_t built) {
  if (stride_ == 0 || built <= 0 || built >= total_ || built % stride_ != 0) return "";
  if (refused_.load(std::memory_order_relaxed)) return "";
  if (built == stride_) {
    // The growth is measured from here: the first items also pay for what
    // all share (arrays reserved for every copy, each touched in 2 MiB
    // pages), which would make the rest look far costlier than it is.
    base_resident_.store(ResidentBytes());
    return "";
  }
  // Growth over at least an eighth of the items: with huge pages the
  // resident size moves 2 MiB at a time per growing array.
  if (built < total_ / 8 || built < 2 * stride_) return "";
  const uint64_t base = base_resident_.load();
  if (base == 0) return "";
  const MemoryRoom room = ReadMemoryRoom(cap_);
  const uint64_t grown = room.resident > base ? room.resident - base : 0;
  std::string verdict = Verdict(items_, total_, built, built - stride_, grown, room);
  if (!verdict.empty() && refused_.exchange(true)) return "";  // said once
  return verdict;
}

std::string MemoryForecast::Reserved(uint64_t bytes) const {
  if (stride_ == 0) return "";
  const MemoryRoom room = ReadMemoryRoom(cap_);
  if (room.available == UINT64_MAX || bytes <= room.available) return "";
  const double each = static_cast<double>(bytes) / static_cast<double>(total_);
  std::ostringstream s;
  s << "not enough memory for " << GroupThousands(total_) << " " << items_
    << ": the arrays reserved for them take " << FormatSize(static_cast<double>(bytes)) << " ("
    << FormatSize(each) << " each) before anything else, and ";
  if (room.available == 0) {
    // Past the room already (a cap below what the program itself holds).
    s << "the process holds " << FormatSize(static_cast<double>(room.resident))
      << " already, with no room left (" << room.bound
      << "). Give the run more memory (README, \"A world that does not fit\")";
  } else {
    const int64_t fit = static_cast<int64_t>(static_cast<double>(room.available) / each);
    s << "the process may take " << FormatSize(static_cast<double>(room.available)) << " more ("
      << room.bound << "). Fewer than " << GroupThousands(fit)
      << " would fit: run fewer robots or give the run more memory (README, \"A world that does "
         "not fit\")";
  }
  s << "; SWARMSIM_MEMORY_CHECK=0 skips this check";
  return s.str();
}

std::string MemoryForecast::ReserveFailed(uint64_t bytes) const {
  const MemoryRoom room = ReadMemoryRoom(cap_);
  std::ostringstream s;
  s << "not enough memory for " << GroupThousands(total_) << " " << items_
    << ": the arrays reserved for them could not be had (" << FormatSize(static_cast<double>(bytes))
    << " had, and more asked for), with the process holding "
    << FormatSize(static_cast<double>(room.resident));
  if (room.available != UINT64_MAX)
    s << " and " << FormatSize(static_cast<double>(room.available)) << " more to take ("
      << room.bound << ")";
  s << ". Run fewer robots or give the run more memory (README, \"A world that does not fit\")";
  return s.str();
}

std::string MemoryForecast::Verdict(const std::string& items, int64_t total, int64_t built,
                                    int64_t measured, uint64_t grown, const MemoryRoom& room) {
  if (measured <= 0 || built >= total || room.available == UINT64_MAX) return "";
  const double each = static_cast<double>(grown) / static_cast<double>(measured);
  const double need = each * static_cast<double>(total - built);
  if (need <= static_cast<double>(room.available)) return "";
  std::ostringstream s;
  s << "not enough memory for " << GroupThousands(total) << " " << items << ": with "
    << GroupThousands(built) << " built, the last " << GroupThousands(measured) << " took "
    << FormatSize(static_cast<double>(grown)) << " (" << FormatSize(each) << " each), so the other "
    << GroupThousands(total - built) << " need about " << FormatSize(need) << " more, and ";
  if (room.available == 0) {
    // The ones built already hold more than the room (a small cap).
    s << "the process holds " << FormatSize(static_cast<double>(room.resident))
      << " already, with no room left (" << room.bound << "). Fewer than " << GroupThousands(built);
  } else {
    const int64_t fit = built + static_cast<int64_t>(static_cast<double>(room.available) / each);
    s << "the process may take " << FormatSize(static_cast<double>(room.available)) << " more ("
      << room.bound << "). About " << GroupThousands(fit);
  }
  s << " would fit: run fewer robots or give the run more memory (README, \"A world that does not "
       "fit\"); SWARMSIM_MEMORY_CHECK=0 skips this check";
  return s.str();
}

}  // namespace swarmsim
