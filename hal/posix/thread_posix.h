/* Threads beside the one that runs the rig (the storage thread, a view processed while the
 * table turns), started with every signal blocked: a stop signal reaches the rig's thread. */
#ifndef THREAD_POSIX_H
#define THREAD_POSIX_H

#include <pthread.h>
#include <stddef.h>

/** Start @p fn(@p arg) on a new thread with every signal blocked.
 *  @param stack_bytes  its stack, 0: the default
 *  @retval 0 @retval -errno (the caller's signal mask is as it was) */
int thread_posix_start(pthread_t *thread, size_t stack_bytes, void *(*fn)(void *), void *arg);

#endif
