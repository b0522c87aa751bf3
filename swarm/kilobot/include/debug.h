/* debug.h: kilolib's serial debugging, for programs swarmsim compiles
 * (swarm/kilobot). With DEBUG defined before including it, printf writes to
 * swarmsim's standard output (a real Kilobot sends it over its serial port);
 * without, printf and debug_init() compile to nothing, as in kilolib. */
#ifndef SWARMSIM_KILOBOT_DEBUG_H_
#define SWARMSIM_KILOBOT_DEBUG_H_

#ifdef DEBUG
#include <stdio.h>
#define debug_init() ((void)0)
#else
#define debug_init()
#define printf(...)
#endif

#endif /* SWARMSIM_KILOBOT_DEBUG_H_ */
