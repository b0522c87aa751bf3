// `swarmsim sweep`: a world over a grid of parameters x seeds, one worker
// process per run, results in a SQLite database, resumable after a kill.
#pragma once

#include <iosfwd>
#include <string>

#include "swarm/sweep/coordinator.h"

namespace swarmsim {

// Parses "i/n" (0 <= i < n). Throws swarmsim::Error.
void ParseShard(const std::string& text, int* index, int* count);

// Runs (or resumes) the sweep. Returns the exit code: 0 when every run of
// this shard has finished and the database holds no failed run, 1 when it
// holds failed or timed-out runs (all the others were still run), 128 +
// the signal when SIGINT, SIGTERM or SIGHUP stopped it (finished runs kept;
// the same command resumes). Throws swarmsim::Error for bad input (exit 2).
int RunSweep(const SweepOptions& options, std::ostream& out, std::ostream& err);

}  // namespace swarmsim
