// `swarmsim merge OUT.db IN.db...`: joins the databases of shards
// (`sweep --shard i/n`) or of separate machines into one. Runs finished in
// an input and not yet in OUT are copied with their metrics and series;
// a run already finished in OUT is kept (never counted twice). Runs still
// missing can be run by `sweep ... --db OUT.db`.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace swarmsim {

int RunMerge(const std::string& out_db, const std::vector<std::string>& inputs,
             bool allow_changed_world, std::ostream& out, std::ostream& err);

}  // namespace swarmsim
