// Best-of-n (n = 2): a swarm of Kilobots agrees on the better of two
// options by the direct modulation of majority-based decisions (Valentini,
// Hamann, Dorigo, AAMAS 2014 / Valentini et al., Frontiers 2016, who ran it
// on 100 Kilobots). Written here from that description and kilolib's
// documentation.
//
// Each robot holds an opinion, option A (0) or B (1), and random-walks.
// It alternates between
//   - exploring (about EXPLORE_TICKS on average, silent): it would be
//     measuring its option's quality; here the qualities are known
//     constants, QUALITY_A and QUALITY_B out of 255, and
//   - disseminating (on average DISSEMINATE_TICKS x quality / 255,
//     broadcasting its opinion): the better option is advertised longer,
//     which is the "direct modulation".
// At the end of dissemination it takes the majority opinion among itself and
// the last two opinions it heard (ties keep its own), then explores again.
// Half the swarm starts with each opinion (even uids A, odd uids B). The
// swarm converges on the option with the higher quality. Swap QUALITY_A and
// QUALITY_B (cc -DQUALITY_A=... with `swarmsim kilobot build ... --
// -DQUALITY_A=128 -DQUALITY_B=255`) and it converges on B.
// LED: red for A, blue for B.
//
//   swarmsim kilobot build worlds/kilobot/best_of_n.c
//   swarmsim run worlds/experiments/best_of_n.yaml
#include <kilolib.h>

#ifndef QUALITY_A
#define QUALITY_A 255
#endif
#ifndef QUALITY_B
#define QUALITY_B 128
#endif
#define EXPLORE_TICKS 320      // ~10 s
#define DISSEMINATE_TICKS 640  // ~20 s for quality 255
#define STEER_TICKS 96         // a new random heading every ~3 s on average

enum state { EXPLORE, DISSEMINATE };
enum motion { STOP, FORWARD, LEFT, RIGHT };

uint8_t opinion = 0;
uint8_t state = EXPLORE;
uint8_t motion = STOP;
uint8_t heard[2] = {255, 255};  // the last two opinions heard (255: none)
uint32_t last_ticks = 0;
message_t message;

// True with probability about 1 / mean_ticks (a geometric duration). Two
// bytes of rand_hard: kilolib's rand_soft is an 8-bit generator whose
// consecutive bytes are far from independent (after a 0 the next byte is
// small), which would erase the difference between the two qualities.
uint8_t ends_now(uint16_t mean_ticks) {
  uint16_t r = ((uint16_t)rand_hard() << 8) | rand_hard();
  return r < 65535u / mean_ticks;
}

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

void show(void) { set_color(opinion == 0 ? RGB(3, 0, 0) : RGB(0, 0, 3)); }

void compose(void) {
  message.type = NORMAL;
  message.data[0] = opinion;
  message.crc = message_crc(&message);
}

void decide(void) {
  uint8_t votes_a = opinion == 0, votes_b = opinion == 1;
  for (uint8_t i = 0; i < 2; ++i) {
    if (heard[i] == 0) ++votes_a;
    if (heard[i] == 1) ++votes_b;
  }
  if (votes_a > votes_b) opinion = 0;
  if (votes_b > votes_a) opinion = 1;
  heard[0] = heard[1] = 255;
  compose();
  show();
}

void setup(void) {
  opinion = kilo_uid % 2;
  compose();
  show();
  last_ticks = kilo_ticks;
}

void loop(void) {
  while (last_ticks != kilo_ticks) {  // once per clock tick
    ++last_ticks;
    if (state == EXPLORE) {
      if (ends_now(EXPLORE_TICKS)) state = DISSEMINATE;
    } else {
      uint16_t quality = opinion == 0 ? QUALITY_A : QUALITY_B;
      uint16_t mean = (uint16_t)((uint32_t)DISSEMINATE_TICKS * quality / 255);
      if (ends_now(mean > 0 ? mean : 1)) {
        decide();
        state = EXPLORE;
      }
    }
    if (motion == STOP || ends_now(STEER_TICKS)) {
      uint8_t r = rand_hard() % 4;
      set_motion(r < 2 ? FORWARD : (r == 2 ? LEFT : RIGHT));
    }
  }
}

message_t* message_tx(void) { return state == DISSEMINATE ? &message : 0; }

void message_rx(message_t* m, distance_measurement_t* d) {
  (void)d;
  if (m->data[0] > 1) return;
  heard[1] = heard[0];
  heard[0] = m->data[0];
}

int main(void) {
  kilo_init();
  kilo_message_tx = message_tx;
  kilo_message_rx = message_rx;
  kilo_start(setup, loop);
  return 0;
}
