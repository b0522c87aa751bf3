// Disperse: robots that start packed together spread out and stop.
//
// Written here from kilolib's documentation as the classic Kilobot
// dispersion: every robot broadcasts (an empty message) and listens. A robot
// that has heard a neighbour closer than TOO_CLOSE_MM during the last
// second keeps moving on a random walk (straight, left or right, a new
// choice every ~2 s from rand_soft); a robot that has heard none stops.
// The swarm ends with every robot at least about TOO_CLOSE_MM from the
// others (as far as the arena allows). LED: red while moving, green once
// stopped.
//
//   swarmsim kilobot build worlds/kilobot/disperse.c
//   swarmsim run worlds/kilobot/disperse.yaml
#include <kilolib.h>

#define TOO_CLOSE_MM 70
#define WINDOW_TICKS 32  // about one second
#define STEER_TICKS 64   // a new random direction about every two seconds

enum motion { STOP, FORWARD, LEFT, RIGHT };

uint8_t motion = STOP;
uint8_t crowded = 0;          // a close neighbour heard in this window
uint8_t crowded_last = 1;     // ... in the previous window (start moving)
uint32_t window_start = 0;
uint32_t last_steer = 0;
message_t message;

void set_motion(uint8_t next) {
  if (next == motion) return;
  motion = next;
  if (next == STOP) {
    set_motors(0, 0);
    return;
  }
  spinup_motors();
  if (next == FORWARD)
    set_motors(kilo_straight_left, kilo_straight_right);
  else if (next == LEFT)
    set_motors(kilo_turn_left, 0);
  else
    set_motors(0, kilo_turn_right);
}

void setup(void) {
  rand_seed(rand_hard());
  message.type = NORMAL;
  message.crc = message_crc(&message);
}

void loop(void) {
  if (kilo_ticks >= window_start + WINDOW_TICKS) {
    crowded_last = crowded;
    crowded = 0;
    window_start = kilo_ticks;
  }
  if (!crowded_last && !crowded) {
    set_motion(STOP);
    set_color(RGB(0, 1, 0));
    return;
  }
  set_color(RGB(1, 0, 0));
  if (motion == STOP || kilo_ticks >= last_steer + STEER_TICKS) {
    last_steer = kilo_ticks;
    uint8_t r = rand_soft() % 4;  // straight half of the time
    set_motion(r < 2 ? FORWARD : (r == 2 ? LEFT : RIGHT));
  }
}

message_t* message_tx(void) { return &message; }

void message_rx(message_t* m, distance_measurement_t* d) {
  (void)m;
  if (estimate_distance(d) < TOO_CLOSE_MM) crowded = 1;
}

int main(void) {
  kilo_init();
  kilo_message_tx = message_tx;
  kilo_message_rx = message_rx;
  kilo_start(setup, loop);
  return 0;
}
