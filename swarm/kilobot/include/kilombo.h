/* kilombo.h: for Kilobot programs written for the Kilombo simulator, which
 * build for a real Kilobot too. swarmsim compiles them as a Kilobot's
 * toolchain does (SIMULATOR is not defined): mydata points to one USERDATA
 * instance, a global, so each robot has its own (like every global here);
 * SET_CALLBACK (Kilombo's simulator hooks) does nothing. */
#ifndef SWARMSIM_KILOBOT_KILOMBO_H_
#define SWARMSIM_KILOBOT_KILOMBO_H_

#include "kilolib.h"

#define REGISTER_USERDATA(UDT) \
  UDT myuserdata;              \
  UDT *mydata = &myuserdata;

#define SET_CALLBACK(ID, CALLBACK)

#endif /* SWARMSIM_KILOBOT_KILOMBO_H_ */
