// Edge following: one robot travels around the edge of a group of
// stationary robots, keeping its distance to the nearest of them.
//
// Written here from kilolib's documentation as the edge-following behaviour
// of Kilobot self-assembly (Rubenstein, Cornejo, Nagpal, Science 2014): the
// mover (kilo_uid 0) takes, over each window of about half a second, the
// smallest distance estimate among the messages it heard, i.e. its nearest
// stationary neighbour; it goes straight, but turns right (towards the
// group) while more than BAND_MM farther than DESIRED_MM and not getting
// closer, and left (away) while too close and not getting farther, so the
// group stays on its right as it goes round (clockwise seen from above). The stationary robots
// (every other uid) only broadcast. LED: the mover red while turning right,
// green while turning left, white while going straight (or when it has heard
// nobody); the group blue.
//
//   swarmsim kilobot build worlds/kilobot/edge_follow.c
//   swarmsim run worlds/kilobot/edge_follow.yaml
#include <kilolib.h>

#define MOVER_UID 0
#define DESIRED_MM 62
#define BAND_MM 6
#define WINDOW_TICKS 16

enum motion { STOP, FORWARD, LEFT, RIGHT };

uint8_t motion = STOP;
uint8_t nearest = 255;       // smallest distance heard in this window (mm)
uint8_t nearest_last = 255;  // ... in the last complete window
uint8_t nearest_before = 255;  // ... in the window before that
uint32_t window_start = 0;
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
  message.type = NORMAL;
  message.crc = message_crc(&message);
  if (kilo_uid != MOVER_UID) set_color(RGB(0, 0, 1));
}

void loop(void) {
  if (kilo_uid != MOVER_UID) return;
  if (kilo_ticks >= window_start + WINDOW_TICKS) {
    nearest_before = nearest_last;
    nearest_last = nearest;
    nearest = 255;
    window_start = kilo_ticks;
    if (nearest_last == 255) {
      set_motion(FORWARD);
      set_color(RGB(1, 1, 1));
    } else if (nearest_last > DESIRED_MM + BAND_MM && nearest_last >= nearest_before) {
      set_motion(RIGHT);
      set_color(RGB(1, 0, 0));
    } else if (nearest_last < DESIRED_MM - BAND_MM && nearest_last <= nearest_before) {
      set_motion(LEFT);
      set_color(RGB(0, 1, 0));
    } else {
      set_motion(FORWARD);
      set_color(RGB(1, 1, 1));
    }
  }
}

message_t* message_tx(void) { return kilo_uid == MOVER_UID ? 0 : &message; }

void message_rx(message_t* m, distance_measurement_t* d) {
  (void)m;
  uint8_t mm = estimate_distance(d);
  if (mm < nearest) nearest = mm;
}

int main(void) {
  kilo_init();
  kilo_message_tx = message_tx;
  kilo_message_rx = message_rx;
  kilo_start(setup, loop);
  return 0;
}
