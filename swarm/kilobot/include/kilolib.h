/* kilolib.h: the Kilobot library's API (kilolib, Harvard SSR / K-Team), for
 * Kilobot programs that swarmsim compiles unchanged with
 * `swarmsim kilobot build prog.c` (swarm/kilobot; worlds/README.md "Kilobot"
 * says how each function behaves in simulation). Written for swarmsim from
 * kilolib's documentation: the same names, types and macros.
 *
 * A program keeps its state in globals: each simulated robot has its own
 * copy of every global (and static) of the program. */
#ifndef SWARMSIM_KILOBOT_KILOLIB_H_
#define SWARMSIM_KILOBOT_KILOLIB_H_

#include <stdint.h>
#include <stdlib.h>

/* rand() is avr-libc's here (0..0x7FFF, runtime/kilolib.c): RAND_MAX too,
 * not the host's 2^31 - 1, whichever of <stdlib.h> and this comes first
 * (`rand() < RAND_MAX / 2` was always true). */
#undef RAND_MAX
#define RAND_MAX 0x7FFF

#include "message.h"
#include "message_crc.h"

/* LED colour from 2-bit channels (0 off .. 3 full): set_color(RGB(0, 3, 0)). */
#define RGB(r, g, b) (((r)&3) | (((g)&3) << 2) | (((b)&3) << 4))
/* kilo_ticks per second (the clock ticks about every 32 ms). */
#define TICKS_PER_SEC 31

/* The two 10-bit signal strengths of a received message. In swarmsim both
 * hold the distance in mm (see estimate_distance). */
typedef struct {
  int16_t low_gain;
  int16_t high_gain;
} distance_measurement_t;

typedef void (*message_rx_t)(message_t *, distance_measurement_t *d);
typedef message_t *(*message_tx_t)(void);
typedef void (*message_tx_success_t)(void);

/* Clock: ticks since the program started, TICKS_PER_SEC a second. */
extern volatile uint32_t kilo_ticks;
/* Clock cycles (8 MHz / 1024) between transmissions: 3906, about 0.5 s. */
extern volatile uint16_t kilo_tx_period;
/* The robot's identifier. */
extern uint16_t kilo_uid;
/* The robot's calibrated duty cycles: set_motors(kilo_turn_left, 0) turns
 * left, set_motors(0, kilo_turn_right) right, and
 * set_motors(kilo_straight_left, kilo_straight_right) goes straight. */
extern uint8_t kilo_turn_left;
extern uint8_t kilo_turn_right;
extern uint8_t kilo_straight_left;
extern uint8_t kilo_straight_right;

/* Called for every message received (register before kilo_start). */
extern message_rx_t kilo_message_rx;
/* Called about twice a second: the message to send, or NULL for none. */
extern message_tx_t kilo_message_tx;
/* Called when the message kilo_message_tx gave went out. */
extern message_tx_success_t kilo_message_tx_success;

#ifdef __cplusplus
extern "C" {
#endif

/* Distance in mm (centre to centre, 33 for touching robots) to the sender of
 * a message, from its signal strengths. */
uint8_t estimate_distance(const distance_measurement_t *d);
/* Waits `ms` milliseconds of simulated time (the robot's motors and LED keep
 * their state meanwhile; see worlds/README.md). */
void delay(uint16_t ms);
/* A random byte from the robot's hardware noise source. */
uint8_t rand_hard();
/* A random byte from kilolib's software generator; rand_seed seeds it. */
uint8_t rand_soft();
void rand_seed(uint8_t seed);
/* Ambient light, 10 bits (0..1023); -1 when it cannot be read. */
int16_t get_ambientlight();
/* Battery voltage and board temperature, 10-bit ADC readings. */
int16_t get_voltage();
int16_t get_temperature();
/* Duty cycles (0..255) of the left and right vibration motors. */
void set_motors(uint8_t left, uint8_t right);
/* Both motors at full power for 15 ms, to start them from rest. */
void spinup_motors();
/* LED colour: RGB(r, g, b). */
void set_color(uint8_t color);
/* Sets up the hardware: call first in main(). */
void kilo_init();
/* Runs setup() once, then loop() over and over. */
void kilo_start(void (*setup)(void), void (*loop)(void));

#ifdef __cplusplus
}
#endif

#endif /* SWARMSIM_KILOBOT_KILOLIB_H_ */
