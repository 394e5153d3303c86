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

struct hal_thread;

/** The firmware's parallel loop (hal_thread.h) on POSIX threads: @p threads of them (0: the
 *  cores online), the caller's and workers started here, at set-up, and kept (a scan starts
 *  none: that would allocate). Loops from several threads take turns. */
void thread_posix_init(struct hal_thread *t, unsigned threads);

#endif
