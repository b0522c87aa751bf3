/* util/delay.h: avr-libc's busy waits. As delay() (kilolib.h), they return
 * at once: a simulated step cannot wait (worlds/README.md "Kilobot"). */
#ifndef SWARMSIM_KILOBOT_UTIL_DELAY_H_
#define SWARMSIM_KILOBOT_UTIL_DELAY_H_
#define _delay_ms(ms) ((void)(ms))
#define _delay_us(us) ((void)(us))
#endif /* SWARMSIM_KILOBOT_UTIL_DELAY_H_ */
