#include "swarm/sweep/sweep.h"

#include <exception>
#include <stdexcept>

#include "framework/error.h"
#include "swarm/sweep/mpi.h"

namespace swarmsim {

void ParseShard(const std::string& text, int* index, int* count) {
  const size_t slash = text.find('/');
  try {
    if (slash == std::string::npos) throw std::invalid_argument("");
    size_t a = 0, b = 0;
    *index = std::stoi(text.substr(0, slash), &a);
    *count = std::stoi(text.substr(slash + 1), &b);
    if (a != slash || b != text.size() - slash - 1) throw std::invalid_argument("");
  } catch (const std::exception&) {
    throw Error("--shard expects i/n (e.g. 0/10 for the first of 10 shards), got '" + text + "'");
  }
  if (*count < 1 || *index < 0 || *index >= *count)
    throw Error("--shard " + text + ": need 0 <= i < n");
}

int RunSweep(const SweepOptions& options, std::ostream& out, std::ostream& err) {
  if (options.mpi) return RunSweepMpi(options, out, err);
  return CoordinateSweep(options, nullptr, out, err);
}

}  // namespace swarmsim
