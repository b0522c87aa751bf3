/* A Kilobot random walk (worlds/kilobot_random_walk.yaml): straight on, or
 * turning left or right, for a random 0.25 to 1.25 s each time; the LED
 * shows what the robot does (green straight, red left, blue right). A plain
 * kilolib program: `swarmsim kilobot build random_walk.c` compiles it
 * unchanged, and so would the Kilobot toolchain. */
#include <kilolib.h>

#define STRAIGHT 0
#define LEFT 1
#define RIGHT 2

uint32_t next_change; /* kilo_ticks at which to choose again */
uint8_t motion;

void set_motion(uint8_t new_motion) {
  if (new_motion == motion) return;
  motion = new_motion;
  spinup_motors();
  if (motion == STRAIGHT) {
    set_motors(kilo_straight_left, kilo_straight_right);
    set_color(RGB(0, 1, 0));
  } else if (motion == LEFT) {
    set_motors(kilo_turn_left, 0);
    set_color(RGB(1, 0, 0));
  } else {
    set_motors(0, kilo_turn_right);
    set_color(RGB(0, 0, 1));
  }
}

void setup() {
  rand_seed(rand_hard());
  motion = 255;
  set_motion(STRAIGHT);
  next_change = kilo_ticks + TICKS_PER_SEC;
}

void loop() {
  if (kilo_ticks >= next_change) {
    set_motion(rand_soft() % 3);
    next_change = kilo_ticks + TICKS_PER_SEC / 4 + rand_soft() % TICKS_PER_SEC;
  }
}

int main() {
  kilo_init();
  kilo_start(setup, loop);
  return 0;
}
