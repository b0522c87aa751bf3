/* A hop-count gradient (worlds/kilobot_gradient.yaml), the classic Kilobot
 * collective: the robot with kilo_uid 0 is the seed (gradient 0); every
 * other robot takes one more than the smallest gradient it hears from a
 * neighbour within 10 cm, and forgets it when it has heard nothing better
 * for 2 s. Everyone sends its own gradient twice a second. The LED shows
 * the gradient modulo 4. A plain kilolib program, compiled unchanged by
 * `swarmsim kilobot build gradient.c`. Messages need the robot's IR
 * transceiver (worlds/models/kilobot.yaml): without one, only the seed
 * knows its gradient. */
#include <kilolib.h>

#define GRADIENT_MAX 255
#define RANGE_MM 100

message_t message;
uint8_t own_gradient = GRADIENT_MAX;
uint8_t heard_gradient = GRADIENT_MAX;
uint8_t heard = 0;
uint32_t last_update = 0;

static const uint8_t colors[4] = {RGB(3, 0, 0), RGB(0, 3, 0), RGB(0, 0, 3), RGB(3, 3, 0)};

message_t *message_tx() {
  message.data[0] = own_gradient;
  message.type = NORMAL;
  message.crc = message_crc(&message);
  return &message;
}

void message_rx(message_t *m, distance_measurement_t *d) {
  if (estimate_distance(d) > RANGE_MM) return;
  if (m->data[0] < heard_gradient) heard_gradient = m->data[0];
  heard = 1;
}

void setup() {
  if (kilo_uid == 0) own_gradient = 0;
}

void loop() {
  if (kilo_uid != 0) {
    if (heard && heard_gradient < GRADIENT_MAX) {
      uint8_t candidate = heard_gradient + 1;
      if (candidate <= own_gradient || kilo_ticks > last_update + 2 * TICKS_PER_SEC) {
        own_gradient = candidate;
        last_update = kilo_ticks;
      }
    } else if (kilo_ticks > last_update + 2 * TICKS_PER_SEC) {
      own_gradient = GRADIENT_MAX;
    }
    heard = 0;
    heard_gradient = GRADIENT_MAX;
  }
  set_color(own_gradient == GRADIENT_MAX ? RGB(0, 0, 0) : colors[own_gradient % 4]);
}

int main() {
  kilo_init();
  kilo_message_rx = message_rx;
  kilo_message_tx = message_tx;
  kilo_start(setup, loop);
  return 0;
}
