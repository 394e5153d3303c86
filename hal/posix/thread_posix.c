/* Threads started with every signal blocked (the new thread inherits the mask in force). */
#define _POSIX_C_SOURCE 200809L
#include "thread_posix.h"

#include "hal_limits.h"
#include "hal_thread.h"

#include <signal.h>
#include <stdatomic.h>
#include <unistd.h>

int thread_posix_start(pthread_t *thread, size_t stack_bytes, void *(*fn)(void *), void *arg)
{
    pthread_attr_t attr;
    sigset_t all, old;
    sigfillset(&all);
    int rc = pthread_attr_init(&attr);
    if (rc != 0)
        return -rc;
    if (stack_bytes > 0)
        rc = pthread_attr_setstacksize(&attr, stack_bytes);
    if (rc == 0 && (rc = pthread_sigmask(SIG_BLOCK, &all, &old)) == 0) {
        rc = pthread_create(thread, &attr, fn, arg);
        pthread_sigmask(SIG_SETMASK, &old, NULL);
    }
    pthread_attr_destroy(&attr);
    return -rc;
}

/* One parallel loop: the items are taken in turn by whichever thread is free. */
struct loop {
    hal_thread_fn fn;
    void *arg;
    unsigned count;
    atomic_uint next;
};

static void loop_items(struct loop *l)
{
    for (unsigned k; (k = atomic_fetch_add(&l->next, 1u)) < l->count;)
        l->fn(l->arg, k);
}

/* The workers, started once when the rig is set up (thread_posix_init), never during a scan:
 * a thread's start allocates, and nothing may once a scan has begun (test_nomalloc). A loop
 * wakes them all; the first `wanted` take part, and the loop ends when those have finished
 * (none joins late: every one of them is counted before the caller returns). */
static struct {
    pthread_mutex_t lock;
    pthread_cond_t wake, done;
    unsigned workers;         /* started */
    unsigned ready;           /* of them, waiting for loops: their start is over */
    unsigned long generation; /* loops so far */
    struct loop *loop;
    unsigned wanted, joined, finished;
} pool = {.lock = PTHREAD_MUTEX_INITIALIZER,
          .wake = PTHREAD_COND_INITIALIZER,
          .done = PTHREAD_COND_INITIALIZER};

static void *pool_worker(void *unused)
{
    (void)unused;
    unsigned long seen = 0;
    pthread_mutex_lock(&pool.lock);
    pool.ready++;
    pthread_cond_broadcast(&pool.done);
    for (;;) {
        while (pool.generation == seen)
            pthread_cond_wait(&pool.wake, &pool.lock);
        seen = pool.generation;
        if (pool.joined >= pool.wanted)
            continue;
        pool.joined++;
        struct loop *l = pool.loop;
        pthread_mutex_unlock(&pool.lock);
        loop_items(l);
        pthread_mutex_lock(&pool.lock);
        pool.finished++;
        pthread_cond_signal(&pool.done);
    }
    return NULL;
}

static void loop_run(void *priv, unsigned threads, unsigned count, hal_thread_fn fn, void *arg)
{
    (void)priv;
    static pthread_mutex_t one_loop = PTHREAD_MUTEX_INITIALIZER; /* callers take turns */
    struct loop l = {.fn = fn, .arg = arg, .count = count};
    atomic_init(&l.next, 0u);
    pthread_mutex_lock(&one_loop);
    pthread_mutex_lock(&pool.lock);
    unsigned helpers = threads - 1u < pool.workers ? threads - 1u : pool.workers;
    pool.loop = &l;
    pool.wanted = helpers;
    pool.joined = pool.finished = 0;
    pool.generation++;
    pthread_cond_broadcast(&pool.wake);
    pthread_mutex_unlock(&pool.lock);
    loop_items(&l); /* the caller's thread takes items too, all of them without helpers */
    pthread_mutex_lock(&pool.lock);
    while (pool.finished < helpers)
        pthread_cond_wait(&pool.done, &pool.lock);
    pool.loop = NULL;
    pthread_mutex_unlock(&pool.lock);
    pthread_mutex_unlock(&one_loop);
}

static const struct hal_thread_ops loop_ops = {.run = loop_run};

void thread_posix_init(struct hal_thread *t, unsigned threads)
{
    if (threads == 0) {
        long online = sysconf(_SC_NPROCESSORS_ONLN);
        threads = online > 0 ? (unsigned)online : 1u;
    }
    threads = threads < HAL_MAX_THREADS ? threads : HAL_MAX_THREADS;
    pthread_mutex_lock(&pool.lock);
    while (pool.workers + 1u < threads) {
        pthread_t worker;
        if (thread_posix_start(&worker, 0, pool_worker, NULL) != 0)
            break; /* fewer helpers: the loops still run, on fewer threads */
        pthread_detach(worker);
        pool.workers++;
    }
    /* Until each is waiting: what a thread's start costs (the C library's and a sanitizer's
     * own allocations) is paid here, at set-up, not in the middle of a scan. */
    while (pool.ready < pool.workers)
        pthread_cond_wait(&pool.done, &pool.lock);
    pthread_mutex_unlock(&pool.lock);
    t->ops = &loop_ops;
    t->priv = NULL;
    t->threads = threads;
}
