/* message_crc.h: the CRC of a Kilobot message, as kilolib documents it
 * (swarm/kilobot). */
#ifndef SWARMSIM_KILOBOT_MESSAGE_CRC_H_
#define SWARMSIM_KILOBOT_MESSAGE_CRC_H_

#include "message.h"

#ifdef __cplusplus
extern "C" {
#endif

/* CRC-16/CCITT (avr-libc's _crc_ccitt_update, start 0xFFFF) of the first 10
 * bytes (data and type). Set msg.crc = message_crc(&msg) before sending:
 * receivers drop messages whose CRC does not match. */
uint16_t message_crc(const message_t *msg);

#ifdef __cplusplus
}
#endif

#endif /* SWARMSIM_KILOBOT_MESSAGE_CRC_H_ */
