// Orbit: one robot circles a stationary one, keeping its distance.
//
// Written here from kilolib's documentation as the classic Kilobot "orbit"
// exercise. The star (kilo_uid 0) stays still and broadcasts; the planet
// (every other robot) uses estimate_distance on each message from the star
// and steers: straight ahead, but turning right (towards the star) while
// it is more than BAND_MM farther than DESIRED_MM and not getting closer,
// and left (away) while it is too close and not getting farther, so that it
// ends up heading along the circle. Started beside the star
// facing along the circle (the star on its right), it goes round clockwise
// and its distance stays in a band about DESIRED_MM. LED: the star blue;
// the planet green while turning left, red while turning right, white while
// going straight.
//
//   swarmsim kilobot build worlds/kilobot/orbit.c
//   swarmsim run worlds/kilobot/orbit.yaml
#include <kilolib.h>

#define STAR_UID 0
#define DESIRED_MM 60
#define BAND_MM 5

enum motion { STOP, FORWARD, LEFT, RIGHT };

uint8_t motion = STOP;
uint8_t distance_mm = 0;
uint8_t previous_mm = 0;  // the distance at the last decision
uint8_t heard = 0;
message_t message;

void set_motion(uint8_t next) {
  if (next == motion) return;
  motion = next;
  if (next == STOP) {
    set_motors(0, 0);
    return;
  }
  spinup_motors();
  if (next == FORWARD) {
    set_motors(kilo_straight_left, kilo_straight_right);
    set_color(RGB(1, 1, 1));
  } else if (next == LEFT) {
    set_motors(kilo_turn_left, 0);
    set_color(RGB(0, 1, 0));
  } else {
    set_motors(0, kilo_turn_right);
    set_color(RGB(1, 0, 0));
  }
}

void setup(void) {
  message.type = NORMAL;
  message.data[0] = 0;
  message.crc = message_crc(&message);
  if (kilo_uid == STAR_UID) set_color(RGB(0, 0, 1));
}

void loop(void) {
  if (kilo_uid == STAR_UID || !heard) return;
  heard = 0;
  // Turn only while the distance moves the wrong way: heading along the
  // circle it stays put, so the planet ends up going round.
  if (distance_mm > DESIRED_MM + BAND_MM && distance_mm >= previous_mm)
    set_motion(RIGHT);
  else if (distance_mm < DESIRED_MM - BAND_MM && distance_mm <= previous_mm)
    set_motion(LEFT);
  else
    set_motion(FORWARD);
  previous_mm = distance_mm;
}

message_t* message_tx(void) { return kilo_uid == STAR_UID ? &message : 0; }

void message_rx(message_t* m, distance_measurement_t* d) {
  (void)m;
  distance_mm = estimate_distance(d);
  heard = 1;
}

int main(void) {
  kilo_init();
  kilo_message_tx = message_tx;
  kilo_message_rx = message_rx;
  kilo_start(setup, loop);
  return 0;
}
