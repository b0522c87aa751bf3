/* message.h: the Kilobot message, as kilolib's message.h documents it,
 * for programs that swarmsim compiles unchanged (swarm/kilobot, worlds/README.md
 * "Kilobot"). Written for swarmsim from kilolib's documentation. */
#ifndef SWARMSIM_KILOBOT_MESSAGE_H_
#define SWARMSIM_KILOBOT_MESSAGE_H_

#include <stdint.h>

/* One IR message: 9 bytes of payload, a type, a CRC (message_crc()); 12
 * bytes, packed, the bytes a Kilobot puts on the air. */
typedef struct __attribute__((__packed__)) {
  uint8_t data[9]; /* payload */
  uint8_t type;    /* message_type_t: below 0x80 for user programs */
  uint16_t crc;    /* message_crc() of the bytes before it */
} message_t;

/* Message types. Types from SPECIAL up are the bootloader's and the
 * overhead controller's: a robot never hands them to kilo_message_rx. */
typedef enum {
  NORMAL = 0,
  GPS,
  SPECIAL = 0x80,
  BOOT = 0x80,
  BOOTPGM_PAGE,
  BOOTPGM_SIZE,
  RESET,
  SLEEP,
  WAKEUP,
  CHARGE,
  VOLTAGE,
  RUN,
  READUID,
  CALIB
} message_type_t;

#endif /* SWARMSIM_KILOBOT_MESSAGE_H_ */
