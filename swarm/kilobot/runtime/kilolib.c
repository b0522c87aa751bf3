/* The per-robot part of the Kilobot runtime: kilolib's globals and
 * functions. It is compiled and linked with the user's program, and its
 * writable data is each robot's own, like the program's (the build renames
 * both objects' data sections; host.c swaps a robot's copy in before calling
 * the program and out after). Nothing here calls swarmsim: the host puts the
 * world's readings into kilobot_rt before each call and reads the motor and
 * LED commands back after it. */
#include <stddef.h>
#include <stdlib.h>

#include "kilobot_runtime.h"

/* Symbols the build renames main to, and the program defines. */
int kilobot_program_main(void);

static void message_rx_dummy(message_t *m, distance_measurement_t *d) {
  (void)m;
  (void)d;
}
static message_t *message_tx_dummy(void) { return NULL; }
static void message_tx_success_dummy(void) {}

/* kilolib's globals (kilolib.h). */
volatile uint32_t kilo_ticks;
volatile uint16_t kilo_tx_period = 3906;
uint16_t kilo_uid;
uint8_t kilo_turn_left;
uint8_t kilo_turn_right;
uint8_t kilo_straight_left;
uint8_t kilo_straight_right;
message_rx_t kilo_message_rx = message_rx_dummy;
message_tx_t kilo_message_tx = message_tx_dummy;
message_tx_success_t kilo_message_tx_success = message_tx_success_dummy;

/* The rest of the robot's runtime state. */
kilobot_robot_t kilobot_rt = {.soft_seed = 0xaa, .libc_rand = 1, .ambient = -1};
void kilo_init() {}

void kilo_start(void (*setup)(void), void (*loop)(void)) {
  kilobot_rt.setup = setup;
  kilobot_rt.loop = loop;
  kilobot_rt.started = 1;
}

/* The host waits: the robot's program is suspended for ms of simulated
 * time (host.c, kilobot_wait). */
void delay(uint16_t ms) { kilobot_wait(ms); }

void set_motors(uint8_t left, uint8_t right) {
  kilobot_rt.motor_left = left;
  kilobot_rt.motor_right = right;
}

void spinup_motors() { set_motors(255, 255); }

void set_color(uint8_t color) { kilobot_rt.color = color & 0x3f; }

int16_t get_ambientlight() { return kilobot_rt.ambient; }
int16_t get_voltage() { return kilobot_rt.voltage; }
int16_t get_temperature() { return kilobot_rt.temperature; }

/* kilolib's software generator, byte for byte: seed 0xaa, accumulator 0. */
uint8_t rand_soft() {
  kilobot_rt.soft_seed ^= (uint8_t)(kilobot_rt.soft_seed << 3);
  kilobot_rt.soft_seed ^= (uint8_t)(kilobot_rt.soft_seed >> 5);
  kilobot_rt.soft_seed ^= (uint8_t)(kilobot_rt.soft_accumulator++ >> 2);
  return kilobot_rt.soft_seed;
}

void rand_seed(uint8_t seed) { kilobot_rt.soft_seed = seed; }

/* The hardware generator: splitmix64 seeded from the robot's random stream
 * (the host seeds it at start), so runs repeat. */
uint8_t rand_hard() {
  uint64_t z = (kilobot_rt.hard_state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return (uint8_t)((z ^ (z >> 31)) >> 56);
}

/* libc's rand()/srand() as avr-libc has them (RAND_MAX 0x7FFF, Park and
 * Miller's minimal standard generator), each robot its own: a program
 * calling rand() gets the sequence a Kilobot gives and runs repeat. */
static int kilobot_do_rand(uint32_t *ctx) {
  long hi, lo, x;
  x = (long)*ctx;
  if (x == 0) x = 123459876L;
  hi = x / 127773L;
  lo = x % 127773L;
  x = 16807L * lo - 2836L * hi;
  if (x < 0) x += 0x7fffffffL;
  *ctx = (uint32_t)x;
  return (int)(x % (0x7fff + 1L));
}
int rand(void) { return kilobot_do_rand(&kilobot_rt.libc_rand); }
void srand(unsigned int seed) { kilobot_rt.libc_rand = seed; }

/* kilolib's message CRC: CRC-16/CCITT as avr-libc's _crc_ccitt_update. */
uint16_t message_crc(const message_t *msg) {
  const uint8_t *bytes = (const uint8_t *)msg;
  uint16_t crc = 0xFFFF;
  for (size_t i = 0; i < sizeof(message_t) - sizeof(msg->crc); i++) {
    uint8_t data = bytes[i];
    data ^= (uint8_t)(crc & 0xff);
    data ^= (uint8_t)(data << 4);
    crc = (uint16_t)((((uint16_t)data << 8) | (crc >> 8)) ^ (uint8_t)(data >> 4) ^
                     ((uint16_t)data << 3));
  }
  return crc;
}

/* Distances travel as mm in both gains (host.c); kilolib's answer is mm. */
uint8_t estimate_distance(const distance_measurement_t *d) {
  const int16_t mm = d->high_gain;
  return (uint8_t)(mm < 0 ? 0 : mm > 255 ? 255 : mm);
}

/* The table host.c exports for this copy. The region's bounds are the
 * linker's (__start_ and __stop_ of the section every writable section of
 * the program and of this file was renamed to: one contiguous region). */
extern char __start_kilo_data[], __stop_kilo_data[];

void kilobot_fill_copy(kilobot_copy_t *c) {
  c->data_begin = __start_kilo_data;
  c->data_end = __stop_kilo_data;
  c->program_main = kilobot_program_main;
  c->robot = &kilobot_rt;
  c->ticks = &kilo_ticks;
  c->tx_period = &kilo_tx_period;
  c->uid = &kilo_uid;
  c->turn_left = &kilo_turn_left;
  c->turn_right = &kilo_turn_right;
  c->straight_left = &kilo_straight_left;
  c->straight_right = &kilo_straight_right;
  c->rx = &kilo_message_rx;
  c->tx = &kilo_message_tx;
  c->tx_success = &kilo_message_tx_success;
}
