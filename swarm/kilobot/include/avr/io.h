/* avr/io.h: the AVR's registers, which a simulated Kilobot does not have.
 * Programs that include it (for a Kilobot's toolchain) compile; a program
 * that uses a register does not (swarm/kilobot, worlds/README.md "Kilobot"). */
#ifndef SWARMSIM_KILOBOT_AVR_IO_H_
#define SWARMSIM_KILOBOT_AVR_IO_H_
#include <stdint.h>
#endif /* SWARMSIM_KILOBOT_AVR_IO_H_ */
