/* kilombo.h: for Kilobot programs written for the Kilombo simulator (which
 * build for a real Kilobot too). REGISTER_USERDATA declares one USERDATA
 * instance and points mydata at it: a global, so each robot has its own,
 * whether SIMULATOR is defined or not. SET_CALLBACK (Kilombo's simulator
 * hooks: botinfo, json_state, ...) does nothing. */
#ifndef SWARMSIM_KILOBOT_KILOMBO_H_
#define SWARMSIM_KILOBOT_KILOMBO_H_

#include "kilolib.h"

#define REGISTER_USERDATA(UDT) \
  UDT myuserdata;              \
  UDT *mydata = &myuserdata;   \
  int UserdataSize = sizeof(UDT);

#define SET_CALLBACK(ID, CALLBACK)

#endif /* SWARMSIM_KILOBOT_KILOMBO_H_ */
