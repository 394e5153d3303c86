/* POSIX clock backend for the appliance. */
#ifndef CLOCK_POSIX_H
#define CLOCK_POSIX_H
#include "hal.h"
/** Fill @p clock with the monotonic POSIX clock. */
void clock_posix_init(struct hal_clock *clock);
#endif
