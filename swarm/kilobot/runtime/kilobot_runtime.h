/* The interface between the per-robot part of the Kilobot runtime
 * (kilolib.c, compiled with the program: its globals are each robot's own)
 * and the host glue (host.c, one per copy of the plugin, shared by the
 * robots that run on that copy). swarm/kilobot/README.md explains the
 * mechanism. */
#ifndef SWARMSIM_KILOBOT_RUNTIME_H_
#define SWARMSIM_KILOBOT_RUNTIME_H_

#include <stdint.h>

#include "kilolib.h"

/* What kilolib.c keeps per robot besides kilolib's own globals: written by
 * the program's calls, read and written by the host between them. */
typedef struct {
  void (*setup)(void); /* kilo_start's */
  void (*loop)(void);
  uint8_t motor_left, motor_right;     /* set_motors' duty cycles */
  uint8_t color;                       /* set_color's */
  uint8_t started;                     /* kilo_start was called */
  int16_t ambient;                     /* get_ambientlight's value this step (-1: none) */
  int16_t voltage, temperature;        /* get_voltage's, get_temperature's */
  uint8_t soft_seed, soft_accumulator; /* rand_soft's generator (kilolib's) */
  uint64_t hard_state;                 /* rand_hard's generator, seeded by the host */
  uint32_t libc_rand;                  /* rand()'s state (avr-libc's algorithm) */
} kilobot_robot_t;

/* Addresses, in one copy of the plugin, of what the host touches. */
typedef struct {
  char *data_begin, *data_end; /* the program's and kilolib.c's writable data */
  int (*program_main)(void);
  kilobot_robot_t *robot;
  volatile uint32_t *ticks;
  volatile uint16_t *tx_period;
  uint16_t *uid;
  uint8_t *turn_left, *turn_right, *straight_left, *straight_right;
  message_rx_t *rx;
  message_tx_t *tx;
  message_tx_success_t *tx_success;
} kilobot_copy_t;

/* delay(ms) (host.c): suspends the robot's setup()/loop() for ms of
 * simulated time when the program runs on a stack of its own (programs that
 * call delay); elsewhere (main(), the message callbacks) it returns at once. */
void kilobot_wait(uint16_t ms);

/* Exported by every copy (host.c): its table. */
const kilobot_copy_t *swarmsim_kilobot_copy(void);

#endif /* SWARMSIM_KILOBOT_RUNTIME_H_ */
