// `swarmsim sweep --mpi` under mpirun (swarm/sweep/mpi.cc): two ranks give the
// results of a local sweep.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "tests/swarm/run_program.h"
#include "tests/swarm/sweep/sweep_db.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

using Result = swarmsim::testing::CommandResult;
using swarmsim::testing::RunCommand;
using swarmsim::testing::RunProgram;
using sweep_testing::Count;
using sweep_testing::kWorld;
using sweep_testing::ReadRuns;
using sweep_testing::RunRow;
using sweep_testing::TempDir;

TEST(SweepTest, MpiTwoRanksGiveTheLocalResults) {
  if (RunCommand("command -v mpirun").exit_code != 0)
    GTEST_SKIP() << "mpirun not found (install openmpi-bin): MPI sweep not tested";
  const fs::path dir = TempDir("mpi");
  const std::string grid = " --param robots=2,3 --seeds 3 --steps 8 --quiet ";
  ASSERT_EQ(RunProgram("sweep " + kWorld + grid + "--db " + (dir / "local.db").string()).exit_code,
            0);
  // Open MPI's plugins leave allocations behind after they are unloaded
  // (reported as "<unknown module>", so no suppression can name them): no
  // leak check of the MPI ranks under AddressSanitizer.
#if defined(__SANITIZE_ADDRESS__)
  const std::string env = "ASAN_OPTIONS=detect_leaks=0 ";
#else
  const std::string env;
#endif
  Result r = RunCommand(env + "mpirun --allow-run-as-root --oversubscribe -np 2 " +
                        std::string(SWARMSIM_BINARY) + " sweep " + kWorld + grid + "--mpi --db " +
                        (dir / "mpi.db").string());
  if (r.output.find("built without MPI") != std::string::npos)
    GTEST_SKIP() << "swarmsim built without MPI";
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto local = ReadRuns(dir / "local.db"), mpi = ReadRuns(dir / "mpi.db");
  ASSERT_EQ(mpi.size(), local.size());
  for (const auto& [id, run] : local) {
    EXPECT_EQ(mpi.at(id).status, "ok");
    EXPECT_EQ(mpi.at(id).hash, run.hash) << id;
  }
  EXPECT_EQ(Count(dir / "mpi.db", "SELECT count(DISTINCT worker) FROM runs"), 2);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim
