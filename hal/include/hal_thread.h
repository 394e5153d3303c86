/* The board's cores for the firmware's per-pixel stages: a parallel loop the platform runs on
 * its threads (POSIX: hal/posix/thread_posix.c), or one item after another where it has none. */
#ifndef HAL_THREAD_H
#define HAL_THREAD_H

#include "hal_limits.h"

/** Parts a stage is cut into a thread (hal_thread_parts), so that one costly part (the object's
 *  middle) does not hold the others up; HAL_MAX_PARTS, the most there can be, sizes the arrays
 *  that keep a result a part. */
#define HAL_PARTS_PER_THREAD 4u
#define HAL_MAX_PARTS (HAL_PARTS_PER_THREAD * HAL_MAX_THREADS)

/** One item of a parallel loop: @p k of the loop's count. Items write disjoint memory. */
typedef void (*hal_thread_fn)(void *arg, unsigned k);

struct hal_thread_ops {
    /** Run @p fn(@p arg, k) for every k below @p count on up to @p threads threads (the
     *  calling one among them: all of them on it when no other can be started) and return
     *  once every item has run. */
    void (*run)(void *priv, unsigned threads, unsigned count, hal_thread_fn fn, void *arg);
};

/** The cores the firmware may use. @c ops NULL (or @c threads 1): one thread. */
struct hal_thread {
    const struct hal_thread_ops *ops;
    void *priv;
    unsigned threads; /**< at most HAL_MAX_THREADS */
};

/** Parts a stage splits into so that its threads stay busy when parts cost unequally (the
 *  image's edges, the object's middle): HAL_PARTS_PER_THREAD a thread, at most @p most (and so
 *  never more than HAL_MAX_PARTS); 1 on one thread. */
unsigned hal_thread_parts(const struct hal_thread *t, unsigned most);

/** Run @p fn for k = 0 .. @p count - 1 on @p t's threads, or one after another here (@p t
 *  NULL, no ops, one thread); every item has run when it returns. */
void hal_thread_run(const struct hal_thread *t, unsigned count, hal_thread_fn fn, void *arg);

#endif
