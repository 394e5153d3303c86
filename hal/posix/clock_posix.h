/* POSIX clock backend for the appliance. */
#ifndef CLOCK_POSIX_H
#define CLOCK_POSIX_H
#include "hal.h"
/** Fill @p clock with the monotonic POSIX clock. */
void clock_posix_init(struct hal_clock *clock);
/** CPU time of the calling thread, in seconds: what a stage costs, whatever else the machine
 *  and the other threads do. */
double clock_posix_thread_cpu_s(void);
/** CPU time of the whole process (every thread), in seconds. */
double clock_posix_process_cpu_s(void);
#endif
