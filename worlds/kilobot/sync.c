// Synchronised blinking: robots that start blinking at random moments end
// up blinking together.
//
// Written here from kilolib's documentation as the classic Kilobot
// synchronisation exercise. Every robot keeps a clock that wraps every
// PERIOD ticks (about 2 s) and flashes its LED for FLASH ticks when it
// wraps. It sends its clock's current value with every message (the value is
// taken in kilo_message_tx, when the message goes out). For each message it
// hears it notes how far ahead the sender's clock is (between -PERIOD/2 and
// PERIOD/2); each time its own clock wraps it moves its clock by a quarter
// of the average of those offsets (what falls below a tick is carried). The clocks of a connected group converge: the
// robots flash together. Robots do not move.
//
//   swarmsim kilobot build worlds/kilobot/sync.c
//   swarmsim run worlds/kilobot/sync.yaml
#include <kilolib.h>

#define PERIOD 64
#define FLASH 6

uint32_t last_ticks = 0;
uint8_t clock = 0;           // 0 .. PERIOD - 1
int16_t offset_sum = 0;
uint8_t offset_count = 0;
int16_t fraction = 0;        // the part of a correction below a tick, in 1/16 ticks
message_t message;

void setup(void) {
  clock = rand_hard() % PERIOD;
  last_ticks = kilo_ticks;
  message.type = NORMAL;
}

void loop(void) {
  while (last_ticks != kilo_ticks) {  // one clock tick per kilo_ticks tick
    ++last_ticks;
    if (++clock >= PERIOD) {
      clock = 0;
      if (offset_count > 0) {
        // A quarter of the mean offset, kept in 1/16 ticks so that what a
        // whole tick cannot hold carries over to the next period (rounding
        // each period would let every hop of the swarm keep a tick or two).
        int16_t correction = (int16_t)(offset_sum * 4 / offset_count) + fraction;
        int16_t shift = correction / 16;
        fraction = correction - shift * 16;
        clock = (uint8_t)((clock + PERIOD + shift) % PERIOD);
      }
      offset_sum = 0;
      offset_count = 0;
    }
  }
  if (clock < FLASH)
    set_color(RGB(3, 3, 0));
  else
    set_color(RGB(0, 0, 0));
}

message_t* message_tx(void) {
  message.data[0] = clock;
  message.crc = message_crc(&message);
  return &message;
}

void message_rx(message_t* m, distance_measurement_t* d) {
  (void)d;
  int16_t ahead = (int16_t)m->data[0] - (int16_t)clock;
  if (ahead > PERIOD / 2) ahead -= PERIOD;
  if (ahead < -PERIOD / 2) ahead += PERIOD;
  if (offset_count < 100) {
    offset_sum += ahead;
    ++offset_count;
  }
}

int main(void) {
  kilo_init();
  kilo_message_tx = message_tx;
  kilo_message_rx = message_rx;
  kilo_start(setup, loop);
  return 0;
}
