#include "swarm/run/version.h"

namespace swarmsim {
const char* Version() { return SWARMSIM_VERSION; }
}  // namespace swarmsim
