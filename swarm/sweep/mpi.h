// `swarmsim sweep --mpi` under mpirun: rank 0 owns the database and hands
// out runs one at a time to whichever rank asks (dynamic assignment, so a
// slow run does not stall the rest); it also runs runs itself. Every rank
// runs its runs as worker processes, like a local sweep. Built only when
// CMake finds MPI (SWARMSIM_HAVE_MPI); otherwise --mpi is a clear error.
#pragma once

#include <iosfwd>

namespace swarmsim {

struct SweepOptions;

bool MpiAvailable();
int RunSweepMpi(const SweepOptions& options, std::ostream& out, std::ostream& err);

}  // namespace swarmsim
