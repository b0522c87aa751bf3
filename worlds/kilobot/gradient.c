// Gradient: every robot learns its hop count from a seed robot.
//
// Written here from kilolib's documentation (kilolib.h: kilo_message_tx,
// kilo_message_rx, message_crc) as the classic Kilobot gradient: the seed
// (kilo_uid 0) holds 0 and every other robot holds one more than the
// smallest value it has heard. Each robot broadcasts its value (kilolib
// sends about twice a second; 255 while it has none, which others ignore). On a
// network whose links are the robots within IR range of each other, every
// value settles to the hop count from the seed (a breadth-first search).
//
// The LED shows the value: value + 1 written in base 4 in the LED's three
// 2-bit channels (red: ones, green: fours, blue: sixteens), so 0 (the seed)
// is dim red, 1 medium red, 3 dim green (RGB(0,1,0)), and so on up to 62;
// a robot with no value yet is dark. Robots do not move.
//
//   swarmsim kilobot build worlds/kilobot/gradient.c
//   swarmsim run worlds/kilobot/gradient.yaml
#include <kilolib.h>

#define SEED_UID 0
#define NO_VALUE 255

uint8_t value = NO_VALUE;
message_t message;

// The LED: value + 1 in base 4 (see above), dark without a value.
void show_value(void) {
  if (value == NO_VALUE) {
    set_color(RGB(0, 0, 0));
  } else {
    uint8_t code = value < 62 ? value + 1 : 63;
    set_color(RGB(code & 3, (code >> 2) & 3, (code >> 4) & 3));
  }
}

void compose_message(void) {
  message.type = NORMAL;
  message.data[0] = value;
  message.crc = message_crc(&message);
}

void setup(void) {
  if (kilo_uid == SEED_UID) value = 0;
  compose_message();
  show_value();
}

void loop(void) {
  // Everything happens as messages arrive.
}

message_t* message_tx(void) { return &message; }

void message_rx(message_t* m, distance_measurement_t* d) {
  (void)d;
  uint8_t heard = m->data[0];
  if (heard < NO_VALUE - 1 && heard + 1 < value) {
    value = heard + 1;
    compose_message();
    show_value();
  }
}

int main(void) {
  kilo_init();
  kilo_message_tx = message_tx;
  kilo_message_rx = message_rx;
  kilo_start(setup, loop);
  return 0;
}
